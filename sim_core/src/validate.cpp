// World::validate(): the invariants of the state arrays at a step boundary.
#include <cmath>
#include <string>

#include "rbsim/core.hpp"

namespace rbsim {

namespace {
Error broken(const std::string& what) {
  return Error{"world invariant broken: " + what};
}
bool positive_finite(double v) {
  return std::isfinite(v) && v > 0;
}
}  // namespace

Status World::validate() const {
  if (!positive_finite(dt_)) return broken("dt is not finite and > 0");
  if (step_ < 0) return broken("negative step index " + std::to_string(step_));
  const std::size_t n = x_.size();
  for (const std::vector<double>* column :
       {&y_, &theta_, &vx_, &vy_, &omega_, &fx_, &fy_, &tau_, &mass_, &inertia_, &radius_}) {
    if (column->size() != n) return broken("a per-body array does not hold one entry per body");
  }
  if (shape_.size() != n) return broken("the shape index does not hold one entry per body");
  const bool rotations = uses_rotations();
  if (rotations && (cos_.size() != n || sin_.size() != n))
    return broken("cos/sin do not hold one entry per body");
  if (wind_moments_.size() != winds_.size() * shapes_.size())
    return broken("one wind moment per wind and shape");
  for (const Shape& s : shapes_) {
    if (s.count < 2 || s.first < 0 || static_cast<std::size_t>(s.first) + s.count > shape_vertices_.size())
      return broken("a shape's vertices out of range");
  }
  for (std::size_t b = 0; b < n; ++b) {
    const auto body = [b](const char* what) { return broken("body " + std::to_string(b) + ": " + what); };
    if (!positive_finite(mass_[b]) || !positive_finite(inertia_[b]) || !positive_finite(radius_[b]))
      return body("mass, inertia and radius must be finite and > 0");
    if (shape_[b] < 0 || static_cast<std::size_t>(shape_[b]) >= shapes_.size())
      return body("shape index out of range");
    // sincos gives the bits of cos() and sin() (step.cpp): equality is exact, NaN aside.
    if (rotations && !std::isnan(theta_[b]) &&
        (cos_[b] != std::cos(theta_[b]) || sin_[b] != std::sin(theta_[b])))
      return body("cos/sin are not those of theta (state written without sync_rotations())");
  }
  if (Status st = validate_identity(); !st) return st;
  for (std::size_t s = 0; s < springs_.size(); ++s) {
    for (const std::int32_t end : {springs_[s].body_i, springs_[s].body_j}) {
      if (end != kFixed && (end < 0 || static_cast<std::size_t>(end) >= n))
        return broken("spring " + std::to_string(s) + ": body index out of range");
    }
  }
  return Ok{};
}

// The ids and the handle table (structure.cpp): one id and one slot per body, ids strictly
// increasing and below the next, each slot naming its body back with the body's generation, and
// every shape's count of bodies right.
Status World::validate_identity() const {
  const std::size_t n = x_.size();
  if (body_ids_.size() != n || body_slot_.size() != n) return broken("one id and one slot per body");
  if (spring_ids_.size() != springs_.size()) return broken("one id per spring");
  if (shape_refs_.size() != shapes_.size()) return broken("one body count per shape");
  for (const std::vector<std::int32_t>* ids : {&body_ids_, &spring_ids_}) {
    const std::int32_t next = ids == &body_ids_ ? next_body_id_ : next_spring_id_;
    for (std::size_t k = 0; k < ids->size(); ++k) {
      if ((*ids)[k] < 0 || (*ids)[k] >= next || (k > 0 && (*ids)[k] <= (*ids)[k - 1]))
        return broken("ids are not strictly increasing below the next id");
    }
  }
  std::size_t live = 0;
  for (const Slot& slot : slots_) live += slot.dense >= 0 ? 1 : 0;
  if (live != n || live + free_slots_.size() != slots_.size())
    return broken("the slot table does not match the bodies");
  for (std::size_t b = 0; b < n; ++b) {
    const std::int32_t slot = body_slot_[b];
    if (slot < 0 || static_cast<std::size_t>(slot) >= slots_.size() ||
        slots_[slot].dense != static_cast<std::int32_t>(b) ||
        slots_[slot].generation != static_cast<std::uint32_t>(body_ids_[b]) + 1)
      return broken("body " + std::to_string(b) + ": its slot does not name it");
  }
  std::int64_t refs = 0;
  std::int32_t dead = 0;
  for (const std::int32_t r : shape_refs_) {
    refs += r;
    dead += r == 0 ? 1 : 0;
  }
  if (refs != static_cast<std::int64_t>(n) || dead != dead_shapes_)
    return broken("the shapes' body counts are wrong");
  for (std::size_t b = 0; b < n; ++b) {
    if (shape_refs_[shape_[b]] == 0)
      return broken("body " + std::to_string(b) + ": its shape counts no body");
  }
  return Ok{};
}

}  // namespace rbsim
