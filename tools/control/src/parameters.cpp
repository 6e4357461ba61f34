// The parameter table: declarations, rclcpp's checks, and applying a value to the state it names.
#include "rbsim/parameters.hpp"

#include "rbsim/assert.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <string_view>
#include <utility>

namespace rbsim::control {

namespace {

constexpr double kMaxDouble = std::numeric_limits<double>::max();
constexpr std::int64_t kMaxInteger = std::numeric_limits<std::int64_t>::max();
constexpr std::int64_t kMaxPointsPerEdge = 1'000'000;  // as the scene loader

std::string shortest(double v) {
  char buffer[32];
  const auto r = std::to_chars(buffer, buffer + sizeof buffer, v);
  return std::string(buffer, r.ptr);
}

ParameterDescriptor read_only(std::string name, ParameterType type, std::string description) {
  ParameterDescriptor d;
  d.name = std::move(name);
  d.type = type;
  d.description = std::move(description);
  d.read_only = true;
  return d;
}

ParameterDescriptor real(std::string name, std::string description, double from, double to) {
  ParameterDescriptor d;
  d.name = std::move(name);
  d.type = ParameterType::Double;
  d.description = std::move(description);
  d.floating_point_range = FloatingPointRange{from, to, 0.0};
  d.additional_constraints = "finite";
  return d;
}

ParameterDescriptor integer(std::string name, std::string description, std::int64_t from, std::int64_t to) {
  ParameterDescriptor d;
  d.name = std::move(name);
  d.type = ParameterType::Integer;
  d.description = std::move(description);
  d.integer_range = IntegerRange{from, to, 0};
  return d;
}

ParameterDescriptor boolean(std::string name, std::string description) {
  ParameterDescriptor d;
  d.name = std::move(name);
  d.type = ParameterType::Bool;
  d.description = std::move(description);
  return d;
}

ParameterDescriptor string(std::string name, std::string description) {
  ParameterDescriptor d;
  d.name = std::move(name);
  d.type = ParameterType::String;
  d.description = std::move(description);
  return d;
}

// Forces in the parameters' numbering: the scene's file order, or gravity then wind for a scene
// made in code.
std::vector<ForceRef> force_order(const Scene& scene) {
  const std::size_t total = scene.world.gravity.size() + scene.world.winds.size();
  if (scene.forces.size() == total) return scene.forces;
  std::vector<ForceRef> order;
  for (std::size_t g = 0; g < scene.world.gravity.size(); ++g)
    order.push_back({ForceRef::Kind::Gravity, static_cast<std::int32_t>(g)});
  for (std::size_t w = 0; w < scene.world.winds.size(); ++w)
    order.push_back({ForceRef::Kind::Wind, static_cast<std::int32_t>(w)});
  return order;
}

// The value of a bound parameter, read from the definition-like state.
ParameterValue read(const ParameterTarget& t, std::span<const GravityDef> gravity,
                    std::span<const WindDef> winds, const SpringDef* spring, const RunSettings& settings,
                    const ParameterValue& current) {
  using K = ParameterTarget::Kind;
  switch (t.kind) {
    case K::Rate:
      return ParameterValue::of_double(settings.rate);
    case K::PublishEvery:
      return ParameterValue::of_integer(settings.publish_every);
    case K::Paused:
      return ParameterValue::of_bool(settings.paused);
    case K::ServiceIntrospection:
      return ParameterValue::of_string(std::string(msgs::to_string(settings.service_introspection)));
    case K::GravityX:
      return ParameterValue::of_double(gravity[t.index].acceleration.x());
    case K::GravityY:
      return ParameterValue::of_double(gravity[t.index].acceleration.y());
    case K::WindBeta:
      return ParameterValue::of_double(winds[t.index].beta);
    case K::WindX:
      return ParameterValue::of_double(winds[t.index].velocity.x());
    case K::WindY:
      return ParameterValue::of_double(winds[t.index].velocity.y());
    case K::WindPoints:
      return ParameterValue::of_integer(winds[t.index].points_per_edge);
    case K::SpringK:
      return ParameterValue::of_double(spring->stiffness);
    case K::SpringL0:
      return ParameterValue::of_double(spring->rest_length);
    default:
      return current;  // read-only and use_sim_time never change
  }
}

}  // namespace

const char* to_string(ParameterType type) {
  switch (type) {
    case ParameterType::NotSet:
      return "not set";
    case ParameterType::Bool:
      return "bool";
    case ParameterType::Integer:
      return "integer";
    case ParameterType::Double:
      return "double";
    case ParameterType::String:
      return "string";
    case ParameterType::ByteArray:
      return "byte_array";
    case ParameterType::BoolArray:
      return "bool_array";
    case ParameterType::IntegerArray:
      return "integer_array";
    case ParameterType::DoubleArray:
      return "double_array";
    case ParameterType::StringArray:
      return "string_array";
  }
  return "unknown type";
}

std::string to_string(const ParameterValue& v) {
  auto join = [](const auto& items, auto text) {
    std::string out = "[";
    for (std::size_t i = 0; i < items.size(); ++i) out += (i ? ", " : "") + text(items[i]);
    return out + "]";
  };
  switch (v.type) {
    case ParameterType::NotSet:
      return "(not set)";
    case ParameterType::Bool:
      return v.bool_value ? "true" : "false";
    case ParameterType::Integer:
      return std::to_string(v.integer_value);
    case ParameterType::Double:
      return shortest(v.double_value);
    case ParameterType::String:
      return "'" + v.string_value + "'";
    case ParameterType::ByteArray:
      return join(v.byte_array_value, [](std::uint8_t b) { return std::to_string(b); });
    case ParameterType::BoolArray:
      return join(v.bool_array_value, [](bool b) { return std::string(b ? "true" : "false"); });
    case ParameterType::IntegerArray:
      return join(v.integer_array_value, [](std::int64_t i) { return std::to_string(i); });
    case ParameterType::DoubleArray:
      return join(v.double_array_value, [](double d) { return shortest(d); });
    case ParameterType::StringArray:
      return join(v.string_array_value, [](const std::string& s) { return "'" + s + "'"; });
  }
  return "?";
}

void ParameterTable::add(ParameterDescriptor descriptor, ParameterValue value, ParameterTarget target) {
  index_.emplace(descriptor.name, entries_.size());
  entries_.push_back({std::move(descriptor), std::move(value), target});
}

ParameterTable::ParameterTable(const Scene& scene, std::int64_t steps, const RunSettings& settings) {
  using K = ParameterTarget::Kind;
  using V = ParameterValue;
  const WorldDef& w = scene.world;
  add(read_only("scene", ParameterType::String, "The scene file"), V::of_string(scene.path), {K::Scene});
  add(read_only("dt", ParameterType::Double, "Time step (s)"), V::of_double(w.dt), {K::Dt});
  add(read_only("integrator", ParameterType::String, "explicit-euler or symplectic-euler"),
      V::of_string(rbsim::to_string(w.integrator)), {K::Integrator});
  add(read_only("bodies", ParameterType::Integer, "Number of rigid bodies"),
      V::of_integer(static_cast<std::int64_t>(w.bodies.size())), {K::Bodies});
  add(read_only("springs", ParameterType::Integer, "Number of springs"),
      V::of_integer(static_cast<std::int64_t>(w.springs.size())), {K::Springs});
  add(read_only("steps", ParameterType::Integer, "Steps per run (the scene's duration / dt, or --duration)"),
      V::of_integer(steps), {K::Steps});
  add(real("rate", "Real-time factor (2 = twice as fast as real time; 0 = as fast as possible)", 0.0,
           kMaxDouble),
      V::of_double(settings.rate), {K::Rate});
  add(integer("publish_every", "Publish every k-th step", 1, kMaxInteger),
      V::of_integer(settings.publish_every), {K::PublishEvery});
  add(boolean("paused", "The run is paused (true) or stepping (false)"), V::of_bool(settings.paused),
      {K::Paused});
  ParameterDescriptor sim_time =
      boolean("use_sim_time", "rbsim is the clock (it publishes /clock): always false");
  sim_time.additional_constraints = "false only";
  add(std::move(sim_time), V::of_bool(false), {K::UseSimTime});
  // rclcpp's NodeTypeDescriptions declares it on every node, read-only, with these words.
  add(read_only("start_type_description_service", ParameterType::Bool,
                "Start the ~/get_type_description service for this node."),
      V::of_bool(settings.start_type_description_service), {K::StartTypeDescriptionService});
  ParameterDescriptor introspection =
      string("service_configure_introspection",
             "Service introspection (REP 2012) of the node's services: events on <service>/_service_event "
             "without (metadata) or with (contents) the request and response");
  introspection.additional_constraints = "disabled, metadata or contents";
  add(std::move(introspection), V::of_string(std::string(msgs::to_string(settings.service_introspection))),
      {K::ServiceIntrospection});
  const std::vector<ForceRef> forces = force_order(scene);
  for (std::size_t i = 0; i < forces.size(); ++i) {
    const std::string p = "forces." + std::to_string(i) + ".";
    const std::int32_t k = forces[i].index;
    if (forces[i].kind == ForceRef::Kind::Gravity) {
      const Vec2 g = w.gravity[k].acceleration;
      add(real(p + "fx", "Gravity: acceleration x (m/s^2)", -kMaxDouble, kMaxDouble), V::of_double(g.x()),
          {K::GravityX, k});
      add(real(p + "fy", "Gravity: acceleration y (m/s^2)", -kMaxDouble, kMaxDouble), V::of_double(g.y()),
          {K::GravityY, k});
    } else {
      const WindDef& wind = w.winds[k];
      add(real(p + "beta", "Wind: drag coefficient per unit edge length", 0.0, kMaxDouble),
          V::of_double(wind.beta), {K::WindBeta, k});
      add(real(p + "fx", "Wind: velocity x (m/s)", -kMaxDouble, kMaxDouble), V::of_double(wind.velocity.x()),
          {K::WindX, k});
      add(real(p + "fy", "Wind: velocity y (m/s)", -kMaxDouble, kMaxDouble), V::of_double(wind.velocity.y()),
          {K::WindY, k});
      add(integer(p + "pointsperedge", "Wind: sample points per hull edge", 2, kMaxPointsPerEdge),
          V::of_integer(wind.points_per_edge), {K::WindPoints, k});
    }
  }
  for (std::size_t j = 0; j < w.springs.size(); ++j)
    add_spring(static_cast<std::int32_t>(j), j, w.springs[j]);
}

void ParameterTable::add_spring(std::int32_t id, std::size_t index, const SpringDef& spring) {
  using K = ParameterTarget::Kind;
  const std::string p = "springs." + std::to_string(id) + ".";
  const auto s = static_cast<std::int32_t>(index);
  add(real(p + "k", "Spring: stiffness (N/m)", 0.0, kMaxDouble), ParameterValue::of_double(spring.stiffness),
      {K::SpringK, s});
  add(real(p + "l0", "Spring: rest length (m)", 0.0, kMaxDouble),
      ParameterValue::of_double(spring.rest_length), {K::SpringL0, s});
  spring_ids_.push_back(id);
}

// The springs' entries come last, two per spring (k, l0), in the world's order, which is the order
// of their ids (ids are never reused; a spring joins at the end, after every spring there). So the
// table follows in place: the entries of springs still there move up over those of removed ones
// (their index in the world moved with them), and new springs' entries are appended. A change costs
// what it changes plus one pass over the ids: a spawn into a world of 10,000 springs does not
// rebuild or move 20,000 entries.
void ParameterTable::follow_structure(const World& world, std::vector<Parameter>* added,
                                      std::vector<std::string>* removed) {
  using K = ParameterTarget::Kind;
  constexpr std::size_t kPerSpring = 2;
  const std::size_t first = entries_.size() - kPerSpring * spring_ids_.size();
  RBSIM_ASSERT(
      std::all_of(entries_.begin() + static_cast<std::ptrdiff_t>(first), entries_.end(),
                  [](const Entry& e) { return e.target.kind == K::SpringK || e.target.kind == K::SpringL0; }),
      "the springs' parameters come last, two per spring");
  for (std::size_t k = 0; k < first; ++k) {
    Entry& e = entries_[k];
    if (e.target.kind == K::Bodies) e.value = ParameterValue::of_integer(world.body_count());
    if (e.target.kind == K::Springs) e.value = ParameterValue::of_integer(world.spring_count());
  }
  std::size_t kept = 0;
  std::int32_t s = 0;  // the world's spring the next kept one must be
  for (std::size_t i = 0; i < spring_ids_.size(); ++i) {
    const std::size_t from = first + kPerSpring * i;
    if (s < world.spring_count() && world.spring_id(SpringId{s}) == spring_ids_[i]) {
      const std::size_t to = first + kPerSpring * kept;
      for (std::size_t k = 0; k < kPerSpring && to != from; ++k) {
        Entry& e = entries_[to + k];
        e = std::move(entries_[from + k]);
        e.target.index = s;
        index_.find(e.descriptor.name)->second = to + k;
      }
      spring_ids_[kept++] = spring_ids_[i];
      ++s;
      continue;
    }
    RBSIM_ASSERT(s == world.spring_count() || world.spring_id(SpringId{s}) > spring_ids_[i],
                 "a spring that joins has an id above every spring there");
    for (std::size_t k = 0; k < kPerSpring; ++k) {
      const std::string& name = entries_[from + k].descriptor.name;
      if (removed != nullptr) removed->push_back(name);
      index_.erase(name);
    }
  }
  entries_.erase(entries_.begin() + static_cast<std::ptrdiff_t>(first + kPerSpring * kept), entries_.end());
  spring_ids_.resize(kept);
  for (; s < world.spring_count(); ++s) {
    add_spring(world.spring_id(SpringId{s}), static_cast<std::size_t>(s), world.spring(SpringId{s}));
    for (std::size_t k = entries_.size() - kPerSpring; added != nullptr && k < entries_.size(); ++k)
      added->push_back({entries_[k].descriptor.name, entries_[k].value});
  }
}

void ParameterTable::follow(const ParameterTable& from) {
  constexpr std::size_t kPerSpring = 2;
  const std::size_t first = entries_.size() - kPerSpring * spring_ids_.size();
  // Not a table of the same scene (a world loaded: other forces, maybe as many): a copy.
  const bool same_scene = first == from.entries_.size() - kPerSpring * from.spring_ids_.size() &&
                          std::equal(entries_.begin(), entries_.begin() + static_cast<std::ptrdiff_t>(first),
                                     from.entries_.begin(), [](const Entry& a, const Entry& b) {
                                       return a.descriptor.name == b.descriptor.name;
                                     });
  if (!same_scene) {
    *this = from;
    return;
  }
  const auto shared =
      std::mismatch(spring_ids_.begin(), spring_ids_.end(), from.spring_ids_.begin(), from.spring_ids_.end());
  const std::size_t keep = first + kPerSpring * static_cast<std::size_t>(shared.first - spring_ids_.begin());
  for (std::size_t i = keep; i < entries_.size(); ++i) index_.erase(entries_[i].descriptor.name);
  entries_.erase(entries_.begin() + static_cast<std::ptrdiff_t>(keep), entries_.end());
  for (std::size_t i = 0; i < keep; ++i) {
    Entry& e = entries_[i];
    const Entry& f = from.entries_[i];
    RBSIM_ASSERT(e.descriptor.name == f.descriptor.name, "a table follows one of the same parameters");
    if (!(e.value == f.value)) e.value = f.value;
    e.target = f.target;
  }
  for (std::size_t i = keep; i < from.entries_.size(); ++i) {
    index_.emplace(from.entries_[i].descriptor.name, i);
    entries_.push_back(from.entries_[i]);
  }
  spring_ids_.assign(from.spring_ids_.begin(), from.spring_ids_.end());
}

std::optional<std::size_t> ParameterTable::find(std::string_view name) const {
  const auto it = index_.find(name);
  if (it == index_.end()) return std::nullopt;
  return it->second;
}

SetParametersResult ParameterTable::check(const Parameter& p, bool at_start) const {
  const auto fail = [](std::string reason) { return SetParametersResult{false, std::move(reason)}; };
  const std::optional<std::size_t> i = find(p.name);
  if (!i) return fail("parameter '" + p.name + "' is not declared");
  const ParameterDescriptor& d = entries_[*i].descriptor;
  const bool given_at_start =
      at_start && entries_[*i].target.kind == ParameterTarget::Kind::StartTypeDescriptionService;
  if (d.read_only && !given_at_start)
    return fail("parameter '" + p.name + "' cannot be set because it is read-only");
  if (p.value.type != d.type) {
    std::string reason = "Wrong parameter type, parameter {" + p.name + "} is of type {" + to_string(d.type) +
                         "}, setting it to {" + to_string(p.value.type) + "} is not allowed.";
    if (d.type == ParameterType::Double && p.value.type == ParameterType::Integer) {
      reason += " (write " + std::to_string(p.value.integer_value) + ".0)";
    }
    return fail(std::move(reason));
  }
  if (d.type == ParameterType::Double) {
    const double v = p.value.double_value;
    const FloatingPointRange& r = *d.floating_point_range;  // every double has one
    if (!std::isfinite(v))
      return fail("Parameter {" + p.name + "} must be finite (got " + shortest(v) + ").");
    if (v < r.from_value || v > r.to_value) {
      return fail("Parameter {" + p.name + "} doesn't comply with floating point range [" +
                  shortest(r.from_value) + ", " + shortest(r.to_value) + "] (got " + shortest(v) + ").");
    }
  }
  if (d.type == ParameterType::Integer) {
    const std::int64_t v = p.value.integer_value;
    const IntegerRange& r = *d.integer_range;  // every integer has one
    if (v < r.from_value || v > r.to_value) {
      return fail("Parameter {" + p.name + "} doesn't comply with integer range [" +
                  std::to_string(r.from_value) + ", " + std::to_string(r.to_value) + "] (got " +
                  std::to_string(v) + ").");
    }
  }
  if (entries_[*i].target.kind == ParameterTarget::Kind::ServiceIntrospection &&
      !msgs::parse_introspection_state(p.value.string_value)) {
    return fail("Parameter {" + p.name + "} must be disabled, metadata or contents (got '" +
                p.value.string_value + "').");
  }
  if (entries_[*i].target.kind == ParameterTarget::Kind::UseSimTime && p.value.bool_value) {
    return fail("parameter 'use_sim_time' cannot be true: rbsim is the clock (it publishes /clock)");
  }
  return SetParametersResult{true, {}};
}

void ParameterTable::refresh(const World& world, const RunSettings& settings) {
  for (Entry& e : entries_) {
    const bool spring =
        e.target.kind == ParameterTarget::Kind::SpringK || e.target.kind == ParameterTarget::Kind::SpringL0;
    e.value = read(e.target, world.gravity(), world.winds(),
                   spring ? &world.spring(SpringId{e.target.index}) : nullptr, settings, e.value);
  }
}

ListParametersResult ParameterTable::list(const std::vector<std::string>& prefixes,
                                          std::uint64_t depth) const {
  ListParametersResult result;
  const auto levels = [](std::string_view s) {
    return static_cast<std::uint64_t>(std::count(s.begin(), s.end(), '.'));
  };
  for (const Entry& e : entries_) {
    const std::string& name = e.descriptor.name;
    bool take = prefixes.empty() && (depth == kDepthRecursive || levels(name) < depth);
    for (const std::string& prefix : prefixes) {
      if (name == prefix) take = true;
      if (name.starts_with(prefix + ".")) {
        take |= depth == kDepthRecursive || levels(std::string_view(name).substr(prefix.size() + 1)) < depth;
      }
    }
    if (!take) continue;
    result.names.push_back(name);
    const std::size_t dot = name.rfind('.');
    if (dot == std::string::npos) continue;
    std::string prefix = name.substr(0, dot);
    if (std::find(result.prefixes.begin(), result.prefixes.end(), prefix) == result.prefixes.end()) {
      result.prefixes.push_back(std::move(prefix));
    }
  }
  return result;
}

bool is_setting(const ParameterTarget& t) {
  using K = ParameterTarget::Kind;
  return t.kind == K::Rate || t.kind == K::PublishEvery || t.kind == K::Paused || t.kind == K::UseSimTime ||
         t.kind == K::ServiceIntrospection;
}

void apply(const ParameterTarget& t, const ParameterValue& v, WorldDef& def) {
  using K = ParameterTarget::Kind;
  switch (t.kind) {
    case K::GravityX:
      def.gravity[t.index].acceleration.x() = v.double_value;
      break;
    case K::GravityY:
      def.gravity[t.index].acceleration.y() = v.double_value;
      break;
    case K::WindBeta:
      def.winds[t.index].beta = v.double_value;
      break;
    case K::WindX:
      def.winds[t.index].velocity.x() = v.double_value;
      break;
    case K::WindY:
      def.winds[t.index].velocity.y() = v.double_value;
      break;
    case K::WindPoints:
      def.winds[t.index].points_per_edge = static_cast<std::int32_t>(v.integer_value);
      break;
    case K::SpringK:
      def.springs[t.index].stiffness = v.double_value;
      break;
    case K::SpringL0:
      def.springs[t.index].rest_length = v.double_value;
      break;
    default:
      break;
  }
}

Status apply(const ParameterTarget& t, const ParameterValue& v, World& world) {
  using K = ParameterTarget::Kind;
  switch (t.kind) {
    case K::GravityX:
    case K::GravityY: {
      Vec2 g = world.gravity()[t.index].acceleration;
      (t.kind == K::GravityX ? g.x() : g.y()) = v.double_value;
      return world.set_gravity(t.index, g);
    }
    case K::WindBeta:
    case K::WindX:
    case K::WindY:
    case K::WindPoints: {
      WindDef wind = world.winds()[t.index];
      if (t.kind == K::WindBeta) wind.beta = v.double_value;
      if (t.kind == K::WindX) wind.velocity.x() = v.double_value;
      if (t.kind == K::WindY) wind.velocity.y() = v.double_value;
      if (t.kind == K::WindPoints) wind.points_per_edge = static_cast<std::int32_t>(v.integer_value);
      return world.set_wind(t.index, wind);
    }
    case K::SpringK:
    case K::SpringL0: {
      const SpringDef& s = world.spring(SpringId{t.index});
      return world.set_spring(SpringId{t.index}, t.kind == K::SpringK ? v.double_value : s.stiffness,
                              t.kind == K::SpringL0 ? v.double_value : s.rest_length);
    }
    default:
      return Ok{};
  }
}

void apply(const ParameterTarget& t, const ParameterValue& v, RunSettings& settings) {
  using K = ParameterTarget::Kind;
  if (t.kind == K::Rate) settings.rate = v.double_value;
  if (t.kind == K::PublishEvery) settings.publish_every = v.integer_value;
  if (t.kind == K::Paused) settings.paused = v.bool_value;
  if (t.kind == K::StartTypeDescriptionService) settings.start_type_description_service = v.bool_value;
  if (t.kind == K::ServiceIntrospection) {
    settings.service_introspection =
        msgs::parse_introspection_state(v.string_value).value_or(settings.service_introspection);
  }
}

Status apply_overrides(const std::vector<ParameterOverride>& overrides, Scene& scene, std::int64_t steps,
                       RunSettings& settings, std::vector<std::string>* warnings) {
  const ParameterTable table(scene, steps, settings);
  for (const ParameterOverride& o : overrides) {
    if (o.wildcard && !table.find(o.parameter.name)) {
      if (warnings != nullptr) {
        warnings->push_back(o.origin + ": warning: parameter '" + o.parameter.name +
                            "' is not one of this node's: ignored");
      }
      continue;
    }
    if (SetParametersResult r = table.check(o.parameter, true); !r.successful) {
      return Error{o.origin + ": parameter '" + o.parameter.name + "': " + r.reason,
                   ErrorCode::InvalidArgument};
    }
  }
  for (const ParameterOverride& o : overrides) {
    const std::optional<std::size_t> i = table.find(o.parameter.name);
    if (!i) continue;  // a skipped wildcard name
    const ParameterTarget t = table.target(*i);
    apply(t, o.parameter.value, scene.world);
    apply(t, o.parameter.value, settings);
  }
  return Ok{};
}

}  // namespace rbsim::control
