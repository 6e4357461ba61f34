// Structural changes between steps: bodies and springs added and removed, their ids and handles.
//
// Every array stays dense and in a stable order (see core.hpp): an addition appends, a removal
// closes the gap. The handle table is Box2D's id pool: a slot per live body, freed slots reused
// last-freed first, a generation per body so that a handle outlives nothing it named.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <numeric>
#include <string>

#include "body_constants.hpp"
#include "finite.hpp"
#include "rbsim/core.hpp"
#include "wind_moments.hpp"

namespace rbsim {

namespace {

Error structure_refused(const std::string& what) {
  return Error{what, ErrorCode::InvalidArgument};
}

// Shapes with no body left are kept (a later body may take them again) until they are more than
// this many and more than half of all shapes; then they are dropped at once, so churn with ever
// new hulls stays bounded by twice the live shapes.
constexpr std::int32_t kDeadShapesBeforeCompaction = 16;

}  // namespace

void World::init_identity() {
  const std::int32_t n = body_count(), s = spring_count();
  body_ids_.resize(n);
  std::iota(body_ids_.begin(), body_ids_.end(), 0);
  body_slot_ = body_ids_;
  slots_.resize(n);
  for (std::int32_t b = 0; b < n; ++b) slots_[b] = Slot{b, static_cast<std::uint32_t>(b) + 1};
  free_slots_.clear();
  spring_ids_.resize(s);
  std::iota(spring_ids_.begin(), spring_ids_.end(), 0);
  next_body_id_ = n;
  next_spring_id_ = s;
}

void World::reserve(std::int32_t bodies, std::int32_t springs) {
  const auto nb = static_cast<std::size_t>(std::max(bodies, 0));
  for (auto* column : {&x_, &y_, &theta_, &vx_, &vy_, &omega_, &fx_, &fy_, &tau_, &cos_, &sin_, &mass_,
                       &inertia_, &radius_}) {
    column->reserve(nb);
  }
  for (auto* column : {&shape_, &body_ids_, &body_slot_, &free_slots_}) column->reserve(nb);
  slots_.reserve(nb);
  springs_.reserve(static_cast<std::size_t>(std::max(springs, 0)));
  spring_ids_.reserve(static_cast<std::size_t>(std::max(springs, 0)));
}

void World::continue_ids(std::int32_t next_body_id, std::int32_t next_spring_id) {
  next_body_id_ = std::max(next_body_id_, next_body_id);
  next_spring_id_ = std::max(next_spring_id_, next_spring_id);
}

BodyHandle World::handle(BodyId b) const {
  const std::int32_t slot = body_slot_[b.index];
  return BodyHandle{slot + 1, slots_[slot].generation};
}

std::optional<BodyId> World::find(BodyHandle h) const {
  if (h.index1 < 1 || static_cast<std::size_t>(h.index1) > slots_.size()) return std::nullopt;
  const Slot& slot = slots_[h.index1 - 1];
  if (slot.dense < 0 || slot.generation != h.generation) return std::nullopt;
  return BodyId{slot.dense};
}

std::optional<BodyId> World::find_body_id(std::int32_t id) const {
  const auto it = std::lower_bound(body_ids_.begin(), body_ids_.end(), id);
  if (it == body_ids_.end() || *it != id) return std::nullopt;
  return BodyId{static_cast<std::int32_t>(it - body_ids_.begin())};
}

std::optional<SpringId> World::find_spring_id(std::int32_t id) const {
  const auto it = std::lower_bound(spring_ids_.begin(), spring_ids_.end(), id);
  if (it == spring_ids_.end() || *it != id) return std::nullopt;
  return SpringId{static_cast<std::int32_t>(it - spring_ids_.begin())};
}

// -- Shapes ----------------------------------------------------------------------------------

std::int32_t World::add_shape(std::span<const Vec2> local) {
  // Bit-identical hulls share a shape, as in create(); a scan, cheap next to a spawn's other work
  // (the count and the first vertex settle almost every comparison).
  const auto shapes = static_cast<std::int32_t>(shapes_.size());
  for (std::int32_t k = 0; k < shapes; ++k) {
    const Shape& shape = shapes_[k];
    if (static_cast<std::size_t>(shape.count) != local.size()) continue;
    if (std::memcmp(shape_vertices_.data() + shape.first, local.data(), local.size() * sizeof(Vec2)) != 0)
      continue;
    if (shape_refs_[k]++ == 0) --dead_shapes_;
    return k;
  }
  shapes_.push_back(
      Shape{static_cast<std::int32_t>(shape_vertices_.size()), static_cast<std::int32_t>(local.size())});
  shape_vertices_.insert(shape_vertices_.end(), local.begin(), local.end());
  shape_refs_.push_back(1);
  // wind_moments_ is [wind * shapes + shape]: each wind's block gains the new shape at its end,
  // inserted from the last block down so the earlier blocks' offsets still hold.
  const auto old = static_cast<std::size_t>(shapes);
  for (std::size_t k = winds_.size(); k-- > 0;) {
    wind_moments_.insert(wind_moments_.begin() + static_cast<std::ptrdiff_t>(k * old + old),
                         compute_wind_moments(local, winds_[k].points_per_edge));
  }
  return shapes;
}

void World::release_shape(std::int32_t shape) {
  if (--shape_refs_[shape] == 0) ++dead_shapes_;
  if (dead_shapes_ > kDeadShapesBeforeCompaction &&
      2 * dead_shapes_ > static_cast<std::int32_t>(shapes_.size())) {
    compact_shapes();
  }
}

void World::compact_shapes() {
  const std::size_t old = shapes_.size();
  std::vector<std::int32_t> remap(old, -1);
  std::vector<Shape> shapes;
  std::vector<Vec2> vertices;
  std::vector<std::int32_t> refs;
  for (std::size_t k = 0; k < old; ++k) {
    if (shape_refs_[k] == 0) continue;
    remap[k] = static_cast<std::int32_t>(shapes.size());
    const Shape& s = shapes_[k];
    shapes.push_back(Shape{static_cast<std::int32_t>(vertices.size()), s.count});
    vertices.insert(vertices.end(), shape_vertices_.begin() + s.first,
                    shape_vertices_.begin() + s.first + s.count);
    refs.push_back(shape_refs_[k]);
  }
  std::vector<WindMoments> moments;
  moments.reserve(winds_.size() * shapes.size());
  for (std::size_t w = 0; w < winds_.size(); ++w) {
    for (std::size_t k = 0; k < old; ++k) {
      if (remap[k] >= 0) moments.push_back(wind_moments_[w * old + k]);
    }
  }
  for (std::int32_t& shape : shape_) shape = remap[shape];
  shapes_ = std::move(shapes);
  shape_vertices_ = std::move(vertices);
  shape_refs_ = std::move(refs);
  wind_moments_ = std::move(moments);
  dead_shapes_ = 0;
}

// -- Bodies ----------------------------------------------------------------------------------

Result<BodyHandle> World::add_body(const BodyDef& def, const BodyState& state) {
  if (Status st = detail::validate_body(def, -1); !st) return st.error();
  if (!finite(state.position) || !std::isfinite(state.theta) || !finite(state.velocity) ||
      !std::isfinite(state.omega)) {
    return structure_refused("added body: state not finite");
  }
  if (next_body_id_ == std::numeric_limits<std::int32_t>::max())
    return structure_refused("no body ids left in this session");
  std::vector<Vec2> local;
  Result<detail::MassProperties> props = detail::mass_properties(def, -1, local);
  if (!props) return props.error();

  const std::int32_t id = next_body_id_++;
  const auto dense = body_count();
  x_.push_back(state.position.x());
  y_.push_back(state.position.y());
  theta_.push_back(state.theta);
  vx_.push_back(state.velocity.x());
  vy_.push_back(state.velocity.y());
  omega_.push_back(state.omega);
  for (auto* column : {&fx_, &fy_, &tau_}) column->push_back(0.0);
  double s = 0.0, c = 1.0;
  ::sincos(state.theta, &s, &c);  // as update_rotations()
  cos_.push_back(c);
  sin_.push_back(s);
  mass_.push_back(props.value().mass);
  inertia_.push_back(props.value().inertia);
  radius_.push_back(def.radius);
  shape_.push_back(add_shape(local));

  std::int32_t slot = 0;
  if (!free_slots_.empty()) {
    slot = free_slots_.back();
    free_slots_.pop_back();
  } else {
    slot = static_cast<std::int32_t>(slots_.size());
    slots_.emplace_back();
  }
  slots_[slot] = Slot{dense, static_cast<std::uint32_t>(id) + 1};
  body_slot_.push_back(slot);
  body_ids_.push_back(id);
  finite_bound_ = compute_finite_bound();  // M and I enter the bound
  return BodyHandle{slot + 1, slots_[slot].generation};
}

void World::erase_body_columns(std::int32_t dense) {
  for (auto* column : {&x_, &y_, &theta_, &vx_, &vy_, &omega_, &fx_, &fy_, &tau_, &cos_, &sin_, &mass_,
                       &inertia_, &radius_}) {
    column->erase(column->begin() + dense);
  }
  for (auto* column : {&shape_, &body_ids_, &body_slot_}) column->erase(column->begin() + dense);
}

Status World::remove_body(BodyHandle body, std::vector<std::int32_t>* removed_springs) {
  const std::optional<BodyId> found = find(body);
  if (!found)
    return structure_refused("no body with handle " + std::to_string(body.index1) + "." +
                             std::to_string(body.generation));
  const std::int32_t d = found->index;

  // The springs attached to it go first; the others keep their order and their ends past d
  // move down with the bodies.
  std::size_t kept = 0;
  for (std::size_t k = 0; k < springs_.size(); ++k) {
    SpringDef sp = springs_[k];
    if (sp.body_i == d || sp.body_j == d) {
      if (removed_springs != nullptr) removed_springs->push_back(spring_ids_[k]);
      continue;
    }
    if (sp.body_i > d) --sp.body_i;
    if (sp.body_j > d) --sp.body_j;
    springs_[kept] = sp;
    spring_ids_[kept] = spring_ids_[k];
    ++kept;
  }
  springs_.resize(kept);
  spring_ids_.resize(kept);

  const std::int32_t shape = shape_[d];
  const std::int32_t slot = body_slot_[d];
  erase_body_columns(d);
  slots_[slot].dense = -1;
  free_slots_.push_back(slot);
  for (std::int32_t b = d; b < body_count(); ++b) slots_[body_slot_[b]].dense = b;
  release_shape(shape);
  finite_bound_ = compute_finite_bound();
  return Ok{};
}

// -- Springs ---------------------------------------------------------------------------------

Result<std::int32_t> World::add_spring(const SpringDef& def) {
  if (Status st = detail::validate_spring(def, body_count(), -1); !st) return st.error();
  if (next_spring_id_ == std::numeric_limits<std::int32_t>::max()) {
    return structure_refused("no spring ids left in this session");
  }
  const bool had_rotations = uses_rotations();
  springs_.push_back(def);
  spring_ids_.push_back(next_spring_id_);
  // cos/sin were not kept while nothing read them: bring them up to theta now.
  if (!had_rotations) update_rotations();
  finite_bound_ = compute_finite_bound();  // k, l0 and the anchors enter the bound
  return next_spring_id_++;
}

Status World::remove_spring(std::int32_t spring_id) {
  const std::optional<SpringId> found = find_spring_id(spring_id);
  if (!found) return structure_refused("no spring with id " + std::to_string(spring_id));
  springs_.erase(springs_.begin() + found->index);
  spring_ids_.erase(spring_ids_.begin() + found->index);
  finite_bound_ = compute_finite_bound();
  return Ok{};
}

}  // namespace rbsim
