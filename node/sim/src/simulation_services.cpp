// simulation_interfaces' services on the node (simulation_services.hpp).
#include "simulation_services.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <future>
#include <limits>
#include <memory>
#include <optional>
#include <regex>

#include "rbsim/scene.hpp"
#include "rbsim/simulation_interfaces.hpp"

namespace rbsim::node {

namespace {

namespace sim = msgs::simulation;
using control::Command;
using control::CommandKind;
using control::CommandResult;
using sim::Result;

// What GetSimulatorFeatures lists: exactly what these services do, and SPAWNABLES when the node
// has a spawnables folder (--spawnables). Not listed, and answered RESULT_FEATURE_UNSUPPORTED: tags
// and convex-hull filters, resetting time or state alone (rbsim's time is its step index, part of
// its state), world tags, setting an acceleration. (QUITTING has no feature of its own: rbsim node
// supports it, SIMULATION_STATE_SETTING. Spawning from a uri has none either: SPAWNING's, with a
// folder; nor loading a world from one: WORLD_LOADING's.) AVAILABLE_WORLDS with a worlds folder.
constexpr sim::Feature kFeatures[] = {
    sim::Feature::Spawning,
    sim::Feature::Deleting,
    sim::Feature::SpawningResourceString,
    sim::Feature::SpawningEntities,
    sim::Feature::SimulationResetSpawned,
    sim::Feature::EntityBounds,
    sim::Feature::EntityBoundsBox,
    sim::Feature::EntityCategories,
    sim::Feature::EntityStateGetting,
    sim::Feature::EntityStateSetting,
    sim::Feature::EntityInfoGetting,
    sim::Feature::SimulationReset,
    sim::Feature::SimulationStateGetting,
    sim::Feature::SimulationStateSetting,
    sim::Feature::SimulationStatePause,
    sim::Feature::StepSimulationSingle,
    sim::Feature::StepSimulationMultiple,
    sim::Feature::StepSimulationAction,
    sim::Feature::WorldLoading,
    sim::Feature::WorldResourceString,
    sim::Feature::WorldUnloading,
    sim::Feature::WorldInfoGetting,
};
// GetSimulatorFeatures.spawn_formats: a FOSSSim scene fragment of one body (rbsim/scene.hpp's
// parse_fragment), as resource_string or a uri (spawning.cpp).
constexpr std::string_view kSpawnFormat = "fosssim-fragment";
constexpr std::size_t kMaxFilterBytes = 256;  // a longer name pattern is refused before it is compiled

using simulation_detail::failure;
using simulation_detail::ok;
using simulation_detail::refuse_malformed;

sim::Vector3 planar(double x, double y) {
  return {x, y, 0.0};
}
sim::Vector3 about_z(double w) {
  return {0.0, 0.0, w};
}

// The body's state as simulation_interfaces says it: header (frame world, stamp the simulated time
// of this boundary), pose (x, y, 0; theta about +z as a unit quaternion), twist (vx, vy, 0;
// 0, 0, omega), acceleration F/M and Gamma/I (N / kg = m/s^2, N m / kg m^2 = rad/s^2) of the
// forces the last step accumulated (zero at step 0 and after a reset: no step has run).
sim::EntityState entity_state(const World& world, BodyId b) {
  sim::EntityState s;
  s.stamp = msgs::sim_time(world);
  s.frame_id = "world";
  const BodyState st = world.state(b);
  s.position = planar(st.position.x(), st.position.y());
  s.orientation = msgs::quaternion_z(st.theta);
  s.linear_velocity = planar(st.velocity.x(), st.velocity.y());
  s.angular_velocity = about_z(st.omega);
  const Vec2 f = world.force(b);
  s.linear_acceleration = planar(f.x() / world.mass(b), f.y() / world.mass(b));
  s.angular_acceleration = about_z(world.torque(b) / world.inertia(b));
  return s;
}

// --- Bounds filters: whether a body's hull (a polygon in the plane z = 0, world frame) overlaps.

// The distance from p to the segment ab.
double distance(const Vec2& p, const Vec2& a, const Vec2& b) {
  const Vec2 ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0.0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (a + t * ab - p).norm();
}
// Whether the segment ab meets the box [lo, hi] (Liang-Barsky clipping of the parameter range).
bool meets_box(const Vec2& a, const Vec2& b, const Vec2& lo, const Vec2& hi) {
  double t0 = 0.0, t1 = 1.0;
  const Vec2 d = b - a;
  for (int k = 0; k < 2; ++k) {
    if (d[k] == 0.0) {
      if (a[k] < lo[k] || a[k] > hi[k]) return false;
      continue;
    }
    double ta = (lo[k] - a[k]) / d[k], tb = (hi[k] - a[k]) / d[k];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t0 > t1) return false;
  }
  return true;
}

struct BoundsFilter {
  sim::BoundsType type = sim::BoundsType::Empty;
  Vec2 lo{0.0, 0.0}, hi{0.0, 0.0};  // Box: the box's extent in the plane z = 0
  Vec2 centre{0.0, 0.0};            // Sphere: its circle in the plane z = 0
  double radius = 0.0;
  bool misses_plane = false;  // the bounds do not reach z = 0: nothing overlaps
};

// Checks the request's bounds; a Result when they are refused.
std::optional<Result> read_bounds(const sim::Bounds& in, BoundsFilter& out) {
  for (const sim::Vector3& p : in.points) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
      return failure(Result::kOperationFailed, "filters.bounds: every point must be finite");
  }
  out.type = static_cast<sim::BoundsType>(in.type);
  switch (out.type) {
    case sim::BoundsType::Empty:
      return std::nullopt;
    case sim::BoundsType::ConvexHull:
      return failure(
          Result::kFeatureUnsupported,
          "filters.bounds: TYPE_CONVEX_HULL is not supported (ENTITY_BOUNDS_CONVEX is not listed)");
    case sim::BoundsType::Box: {
      if (in.points.size() != 2)
        return failure(Result::kOperationFailed,
                       "filters.bounds: TYPE_BOX takes 2 points (two opposite corners), got " +
                           std::to_string(in.points.size()));
      const sim::Vector3 &a = in.points[0], &b = in.points[1];
      out.lo = {std::min(a.x, b.x), std::min(a.y, b.y)};
      out.hi = {std::max(a.x, b.x), std::max(a.y, b.y)};
      out.misses_plane = std::min(a.z, b.z) > 0.0 || std::max(a.z, b.z) < 0.0;
      return std::nullopt;
    }
    case sim::BoundsType::Sphere: {
      if (in.points.size() != 2 || in.points[1].x < 0.0)
        return failure(Result::kOperationFailed,
                       "filters.bounds: TYPE_SPHERE takes 2 points (the centre, then the radius >= 0 as x)");
      const sim::Vector3& c = in.points[0];
      const double r = in.points[1].x;
      out.centre = {c.x, c.y};
      out.misses_plane = std::abs(c.z) > r;
      out.radius = out.misses_plane ? 0.0 : std::sqrt(r * r - c.z * c.z);  // its circle at z = 0
      return std::nullopt;
    }
  }
  return failure(Result::kOperationFailed, "filters.bounds: unknown type " + std::to_string(in.type));
}

bool overlaps(const BoundsFilter& f, std::span<const Vec2> hull) {
  if (f.type == sim::BoundsType::Empty) return true;
  if (f.misses_plane) return false;
  const bool box = f.type == sim::BoundsType::Box;
  if (polygon_contains(hull, box ? Vec2(0.5 * (f.lo + f.hi)) : f.centre)) return true;
  for (std::size_t i = 0, j = hull.size() - 1; i < hull.size(); j = i++) {
    if (box ? meets_box(hull[j], hull[i], f.lo, f.hi) : distance(f.centre, hull[j], hull[i]) <= f.radius)
      return true;
  }
  return false;
}

// The request's filters, checked once (a Result when they are refused), then applied per body.
struct Filters {
  std::optional<std::regex> name;
  bool dynamic_objects = true;  // every body is CATEGORY_DYNAMIC_OBJECT: whether the categories take it
  BoundsFilter bounds;

  std::optional<Result> read(const sim::EntityFilters& in) {
    if (!in.tags.tags.empty())
      return failure(Result::kFeatureUnsupported,
                     "filters.tags: entity tags are not supported (ENTITY_TAGS is not listed)");
    if (in.filter.size() > kMaxFilterBytes)
      return failure(Result::kOperationFailed,
                     "filters.filter: longer than " + std::to_string(kMaxFilterBytes) + " bytes");
    if (!in.filter.empty()) {
      try {
        name.emplace(in.filter, std::regex::extended | std::regex::nosubs);
      } catch (const std::regex_error& e) {
        return failure(Result::kOperationFailed, "filters.filter: not a POSIX extended regular expression (" +
                                                     std::string(e.what()) + ")");
      }
    }
    dynamic_objects =
        in.categories.empty() ||
        std::find(in.categories.begin(), in.categories.end(),
                  static_cast<std::uint8_t>(sim::Category::DynamicObject)) != in.categories.end();
    return read_bounds(in.bounds, bounds);
  }

  // The bodies that pass (dense indices), in body order; `names` the bodies' names (Entities),
  // `hull` scratch.
  std::vector<std::int32_t> select(const World& world, const std::vector<std::string>& names,
                                   std::vector<Vec2>& hull) const {
    std::vector<std::int32_t> out;
    if (!dynamic_objects) return out;
    for (std::int32_t i = 0; i < world.body_count(); ++i) {
      if (name && !std::regex_search(names[static_cast<std::size_t>(i)], *name)) continue;
      // The hull in world axes only for a bounds filter: its vertices cost a sine and a cosine
      // each, most of a reply's own CPU without one (get_entities_states of every body).
      if (bounds.type != sim::BoundsType::Empty) {
        const BodyId b{i};
        hull.resize(world.hull(b).size());
        for (std::size_t v = 0; v < hull.size(); ++v)
          hull[v] = world.world_vertex(b, static_cast<std::int32_t>(v));
        if (!overlaps(bounds, hull)) continue;
      }
      out.push_back(i);
    }
    return out;
  }
};

// Runs `f(world)` on the run loop's thread at the next step boundary at or after `at_step`
// (Controller::read) and waits up to `timeout_s` for it; nullopt when it timed out or the run
// ended first.
template <class F>
auto at_boundary(control::Controller& controller, double timeout_s, F f, std::int64_t at_step = 0)
    -> std::optional<decltype(f(std::declval<const World&>()))> {
  using T = decltype(f(std::declval<const World&>()));
  auto promise = std::make_shared<std::promise<std::optional<T>>>();
  std::future<std::optional<T>> answer = promise->get_future();
  controller.read(
      [promise, f = std::move(f)](const World* world) {
        promise->set_value(world ? std::optional<T>(f(*world)) : std::nullopt);
      },
      at_step);
  if (answer.wait_for(std::chrono::duration<double>(timeout_s)) != std::future_status::ready)
    return std::nullopt;
  return answer.get();
}

std::string no_entity(const std::string& name) {
  return "no entity '" + name + "' (get_entities lists them)";
}

Result unanswered(double timeout_s) {
  return failure(Result::kOperationFailed, "the run loop did not reach a step boundary within " +
                                               std::to_string(timeout_s) + " s (or the run ended)");
}

}  // namespace

void SimulationServices::add(std::vector<Entry>& out) {
  out.emplace_back(
      "get_simulator_features", std::string(sim::GetSimulatorFeaturesRequest::kService),
      typed_handler<sim::GetSimulatorFeaturesRequest, sim::GetSimulatorFeaturesResponse>(
          [this](const RequestHeader&, const sim::GetSimulatorFeaturesRequest&) {
            sim::GetSimulatorFeaturesResponse res;
            for (const sim::Feature f : kFeatures)
              res.features.features.push_back(static_cast<std::uint16_t>(f));
            if (!spawnables_.empty())
              res.features.features.push_back(static_cast<std::uint16_t>(sim::Feature::Spawnables));
            if (!worlds_.empty())
              res.features.features.push_back(static_cast<std::uint16_t>(sim::Feature::AvailableWorlds));
            res.features.spawn_formats.emplace_back(kSpawnFormat);
            res.features.custom_info =
                "rbsim: every body is an entity (CATEGORY_DYNAMIC_OBJECT), a scene's named body_<id>, a "
                "spawned one as spawned; spawn_formats: a FOSSSim scene fragment of one body as "
                "resource_string, or as a uri naming a file of the node's spawnables folder (rbsim node "
                "--spawnables DIR; get_spawnables lists them); worlds: FOSSSim scenes, as "
                "resource_string or a uri naming a file of the node's worlds folder (rbsim node --worlds "
                "DIR, the bundled scenes by default; get_available_worlds lists them); state changes, "
                "spawns, deletes and world loads are recorded on <node>/commands (a fragment's or scene's "
                "text, not its path) and re-simulate exactly";
            return res;
          },
          [](const Error&) { return std::optional<sim::GetSimulatorFeaturesResponse>(); }));
  add_state(out);
  add_entities(out);
  add_spawning(out);
  add_worlds(out);
}

// Simulation state, reset and stepping. The state is read at a boundary: STOPPED while stopped_ is
// set and the world is paused at step 0, else PAUSED or PLAYING as the run's `paused` setting.
void SimulationServices::add_state(std::vector<Entry>& out) {
  const auto state_now = [this]() -> std::optional<sim::State> {
    // Quitting, the loop may be gone: no boundary to wait for.
    if (quitting_.load()) return sim::State::Quitting;
    if (loading_.load()) return sim::State::LoadingWorld;
    return at_boundary(controller_, timeout_s_, [this](const World& world) {
      if (!controller_.world_info().loaded) return sim::State::NoWorld;
      const bool paused = controller_.settings().paused;
      if (paused && world.step_index() == 0 && stopped_.load()) return sim::State::Stopped;
      return paused ? sim::State::Paused : sim::State::Playing;
    });
  };
  const auto command = [this](CommandKind kind) {
    Command c;
    c.kind = kind;
    return apply_(std::move(c));
  };
  out.emplace_back(
      "get_simulation_state", std::string(sim::GetSimulationStateRequest::kService),
      typed_handler<sim::GetSimulationStateRequest, sim::GetSimulationStateResponse>(
          [this, state_now](const RequestHeader&, const sim::GetSimulationStateRequest&) {
            const std::optional<sim::State> st = state_now();
            if (!st) return sim::GetSimulationStateResponse{0, unanswered(timeout_s_)};
            return sim::GetSimulationStateResponse{static_cast<std::uint8_t>(*st), ok()};
          },
          [](const Error& e) {
            return std::optional<sim::GetSimulationStateResponse>(
                sim::GetSimulationStateResponse{0, failure(Result::kOperationFailed, e.message)});
          }));
  out.emplace_back(
      "set_simulation_state", std::string(sim::SetSimulationStateRequest::kService),
      typed_handler<sim::SetSimulationStateRequest, sim::SetSimulationStateResponse>(
          [this, state_now, command](const RequestHeader&, const sim::SetSimulationStateRequest& req) {
            return sim::SetSimulationStateResponse{set_state(req.state, state_now, command)};
          },
          refuse_malformed<sim::SetSimulationStateResponse>()));
  out.emplace_back(
      "reset_simulation", std::string(sim::ResetSimulationRequest::kService),
      typed_handler<sim::ResetSimulationRequest, sim::ResetSimulationResponse>(
          [command](const RequestHeader&, const sim::ResetSimulationRequest& req) {
            using R = sim::ResetSimulationRequest;
            // Time and state are one in rbsim (the step index is part of the world's
            // state): a reset of both is the full one. SCOPE_SPAWNED alone removes what was
            // spawned, the scene's bodies left as they are.
            if (req.scope == R::kScopeSpawned) {
              const CommandResult r = command(CommandKind::ResetSpawned);
              return sim::ResetSimulationResponse{
                  r.successful ? ok() : failure(Result::kOperationFailed, r.message)};
            }
            if (req.scope != R::kScopeDefault && req.scope != R::kScopeAll &&
                req.scope != (R::kScopeTime | R::kScopeState)) {
              return sim::ResetSimulationResponse{
                  failure(Result::kFeatureUnsupported, "scope " + std::to_string(req.scope) +
                                                           ": only SCOPE_DEFAULT, SCOPE_ALL or SCOPE_TIME | "
                                                           "SCOPE_STATE (a full reset to step 0), or "
                                                           "SCOPE_SPAWNED")};
            }
            const CommandResult r = command(CommandKind::Reset);
            return sim::ResetSimulationResponse{r.successful ? ok()
                                                             : failure(Result::kOperationFailed, r.message)};
          },
          refuse_malformed<sim::ResetSimulationResponse>()));
  out.emplace_back("step_simulation", std::string(sim::StepSimulationRequest::kService),
                   typed_handler<sim::StepSimulationRequest, sim::StepSimulationResponse>(
                       [this](const RequestHeader&, const sim::StepSimulationRequest& req) {
                         return sim::StepSimulationResponse{step(req.steps)};
                       },
                       refuse_malformed<sim::StepSimulationResponse>()));
}

// SetSimulationState's transitions: to PLAYING a resume, to PAUSED a pause (from STOPPED: paused
// at step 0, no step taken), to STOPPED a pause and a reset to step 0; the same state again
// ALREADY_IN_TARGET_STATE; QUITTING ends the node as a SIGINT does (the reply goes out first), after
// which every other state is INCORRECT_TRANSITION; NO_WORLD, LOADING_WORLD and unknown values are
// INCORRECT_TRANSITION. With no world, PLAYING and STOPPED fail (STATE_TRANSITION_ERROR: nothing
// to run or reset) and PAUSED is ALREADY_IN_TARGET_STATE's or a pause.
Result SimulationServices::set_state(std::uint8_t target, const StateNow& state_now, const Run& command) {
  using R = sim::SetSimulationStateResponse;
  const auto to = static_cast<sim::State>(target);
  if (to == sim::State::Quitting) {
    if (!quit_)
      return failure(Result::kFeatureUnsupported,
                     "STATE_QUITTING is not supported here: stop the node with SIGINT or SIGTERM");
    if (quitting_.exchange(true)) return failure(R::kAlreadyInTargetState, "already quitting");
    quit_();
    return ok();
  }
  if (quitting_.load()) return failure(R::kIncorrectTransition, "the node is quitting");
  if (to != sim::State::Playing && to != sim::State::Paused && to != sim::State::Stopped)
    return failure(
        R::kIncorrectTransition,
        "state " + std::to_string(target) +
            ": not a state to set (NO_WORLD and LOADING_WORLD come of unload_world and load_world)");
  const std::optional<sim::State> now = state_now();
  if (!now) return unanswered(timeout_s_);
  if (*now == to) return failure(R::kAlreadyInTargetState, "already in the target state");
  std::vector<CommandKind> kinds;
  if (to == sim::State::Playing) kinds = {CommandKind::Resume};
  if (to == sim::State::Paused) kinds = {CommandKind::Pause};
  if (to == sim::State::Stopped) kinds = {CommandKind::Pause, CommandKind::Reset};
  for (const CommandKind k : kinds) {
    const CommandResult r = command(k);
    if (!r.successful) return failure(R::kStateTransitionError, r.message);
  }
  stopped_.store(to == sim::State::Stopped);
  return ok();
}

// StepSimulation: only while paused (RESULT_OPERATION_FAILED otherwise, as the definition says);
// answered once the world reached the step `steps` past the boundary the step command applied at.
Result SimulationServices::step(std::uint64_t steps) {
  if (steps == 0 || steps > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max()))
    return failure(Result::kOperationFailed,
                   "steps must be in [1, 2^63) (got " + std::to_string(steps) + ")");
  Command c;
  c.kind = CommandKind::Step;
  c.steps = static_cast<std::int64_t>(steps);
  const CommandResult r = apply_(std::move(c));
  if (!r.successful) return failure(Result::kOperationFailed, r.message);
  stopped_.store(false);
  const std::int64_t target = r.step + static_cast<std::int64_t>(steps);
  // Stepping takes its own time: at most the run's pace for these steps, on top of the wait.
  const control::RunSettings settings = controller_.settings();
  const double dt = controller_.world_info().dt;
  const double pace = settings.rate > 0.0 ? static_cast<double>(steps) * dt / settings.rate : 0.0;
  const std::optional<std::int64_t> reached = at_boundary(
      controller_, timeout_s_ + 2.0 * pace, [](const World& w) { return w.step_index(); }, target);
  if (!reached) return unanswered(timeout_s_ + 2.0 * pace);
  if (*reached < target) {
    return failure(Result::kOperationFailed, "stepping stopped at step " + std::to_string(*reached) +
                                                 " short of step " + std::to_string(target) +
                                                 " (a reset or a pause came first)");
  }
  return ok();
}

std::optional<Result> planar_pose(const sim::Vector3& p, const msgs::Quaternion& q, std::uint8_t invalid,
                                  Vec2& position, double& theta) {
  const double norm = std::sqrt(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w);
  for (double v : {p.x, p.y, p.z, q.x, q.y, q.z, q.w}) {
    if (!std::isfinite(v)) return failure(invalid, "the pose must be finite");
  }
  if (p.z != 0.0) return failure(invalid, "position.z must be 0 (a planar world)");
  // A unit quaternion of a rotation about +z: (0, 0, sin(theta/2), cos(theta/2)).
  if (std::abs(norm - 1.0) > 1e-9) return failure(invalid, "the orientation is not a unit quaternion");
  if (std::abs(q.x) > 1e-9 || std::abs(q.y) > 1e-9)
    return failure(invalid, "the orientation must be a rotation about z (x and y 0)");
  position = Vec2(p.x, p.y);
  theta = 2.0 * std::atan2(q.z, q.w);
  return std::nullopt;
}

// Checks SetEntityState's request against a planar world and makes its StateArgs (body unset): a
// Result when it is refused.
std::optional<Result> state_args(const sim::SetEntityStateRequest& req, control::StateArgs& a) {
  using R = sim::SetEntityStateResponse;
  const sim::EntityState& s = req.state;
  if (req.set_acceleration) {
    return failure(Result::kFeatureUnsupported,
                   "set_acceleration: a body's acceleration is its forces' (gravity, springs, wind) over its "
                   "mass and inertia; set the pose or the twist");
  }
  if (!s.frame_id.empty() && s.frame_id != "world")
    return failure(Result::kOperationFailed,
                   "state.header.frame_id '" + s.frame_id + "': only 'world' (or empty)");
  if (req.set_pose) {
    if (std::optional<Result> bad =
            planar_pose(s.position, s.orientation, R::kInvalidPose, a.position, a.theta))
      return bad;
    a.set_pose = true;
  }
  if (req.set_twist) {
    const sim::Vector3 &v = s.linear_velocity, &w = s.angular_velocity;
    for (double x : {v.x, v.y, v.z, w.x, w.y, w.z}) {
      if (!std::isfinite(x)) return failure(Result::kOperationFailed, "the twist must be finite");
    }
    if (v.z != 0.0 || w.x != 0.0 || w.y != 0.0)
      return failure(Result::kOperationFailed,
                     "a planar world: twist.linear.z, angular.x and angular.y must be 0");
    a.set_twist = true;
    a.velocity = Vec2(v.x, v.y);
    a.omega = w.z;
  }
  return std::nullopt;
}

// SetEntityState: the pose and/or twist as a command, applied at the next step boundary (while
// paused, the current one: a get right after the reply reads the new state).
Result SimulationServices::set_entity_state(const sim::SetEntityStateRequest& req) {
  Command c;
  c.kind = CommandKind::SetState;
  if (std::optional<Result> refused = state_args(req, c.state)) return *refused;
  if (!c.state.set_pose && !c.state.set_twist)
    return failure(Result::kOk, "nothing to set (set_pose and set_twist false)");
  const std::optional<std::optional<std::int32_t>> id = at_boundary(
      controller_, timeout_s_, [this, entity = req.entity](const World& w) -> std::optional<std::int32_t> {
        const std::optional<std::int32_t> found = controller_.find_entity(entity);
        return found && w.find_body_id(*found) ? found : std::nullopt;
      });
  if (!id) return unanswered(timeout_s_);
  if (!*id) return failure(Result::kNotFound, no_entity(req.entity));
  c.state.body = **id;
  const CommandResult r = apply_(std::move(c));
  // Deleted between the look-up and the boundary the command applied at.
  if (r.refusal == control::Refusal::NoSuchEntity) return failure(Result::kNotFound, r.message);
  return r.successful ? ok() : failure(Result::kOperationFailed, r.message);
}

// The entities: every body, body_<i>, CATEGORY_DYNAMIC_OBJECT.
void SimulationServices::add_entities(std::vector<Entry>& out) {
  // The world at a boundary, then the answer made from it: f(world) returns the response.
  const auto read = [this](auto f) { return at_boundary(controller_, timeout_s_, std::move(f)); };
  out.emplace_back("get_entities", std::string(sim::GetEntitiesRequest::kService),
                   typed_handler<sim::GetEntitiesRequest, sim::GetEntitiesResponse>(
                       [this, read](const RequestHeader&, const sim::GetEntitiesRequest& req) {
                         auto filters = std::make_shared<Filters>();
                         if (std::optional<Result> bad = filters->read(req.filters))
                           return sim::GetEntitiesResponse{*bad, {}};
                         std::optional<sim::GetEntitiesResponse> res = read([this, filters](const World& w) {
                           std::vector<Vec2> hull;
                           sim::GetEntitiesResponse r{ok(), {}};
                           const std::vector<std::string>& names = controller_.entities()->body_names;
                           for (const std::int32_t i : filters->select(w, names, hull))
                             r.entities.push_back(names[static_cast<std::size_t>(i)]);
                           return r;
                         });
                         return res ? std::move(*res) : sim::GetEntitiesResponse{unanswered(timeout_s_), {}};
                       },
                       refuse_malformed<sim::GetEntitiesResponse>()));
  out.emplace_back(
      "get_entities_states", std::string(sim::GetEntitiesStatesRequest::kService),
      typed_handler<sim::GetEntitiesStatesRequest, sim::GetEntitiesStatesResponse>(
          [this, read](const RequestHeader&, const sim::GetEntitiesStatesRequest& req) {
            auto filters = std::make_shared<Filters>();
            if (std::optional<Result> bad = filters->read(req.filters))
              return sim::GetEntitiesStatesResponse{*bad, {}, {}};
            std::optional<sim::GetEntitiesStatesResponse> res = read([this, filters](const World& w) {
              std::vector<Vec2> hull;
              sim::GetEntitiesStatesResponse r{ok(), {}, {}};
              const std::vector<std::string>& names = controller_.entities()->body_names;
              for (const std::int32_t i : filters->select(w, names, hull)) {
                r.entities.push_back(names[static_cast<std::size_t>(i)]);
                r.states.push_back(entity_state(w, BodyId{i}));
              }
              return r;
            });
            return res ? std::move(*res) : sim::GetEntitiesStatesResponse{unanswered(timeout_s_), {}, {}};
          },
          refuse_malformed<sim::GetEntitiesStatesResponse>()));
  add_entity(out);
}

// The services on one entity, named in the request: NOT_FOUND for a name no body has.
void SimulationServices::add_entity(std::vector<Entry>& out) {
  // f(world, body) makes the response's payload at a boundary; `Res` carries it with the result.
  const auto one = [this]<class Res, class Payload>(const std::string& entity, auto f) -> Res {
    std::optional<std::optional<Payload>> got =
        at_boundary(controller_, timeout_s_, [this, entity, f](const World& w) -> std::optional<Payload> {
          const std::optional<std::int32_t> id = controller_.find_entity(entity);
          const std::optional<BodyId> b = id ? w.find_body_id(*id) : std::nullopt;
          if (!b) return std::nullopt;
          return f(w, *b);
        });
    if (!got) return Res{unanswered(timeout_s_), {}};
    if (!*got) return Res{failure(Result::kNotFound, no_entity(entity)), {}};
    return Res{ok(), std::move(**got)};
  };
  out.emplace_back("get_entity_info", std::string(sim::GetEntityInfoRequest::kService),
                   typed_handler<sim::GetEntityInfoRequest, sim::GetEntityInfoResponse>(
                       [one](const RequestHeader&, const sim::GetEntityInfoRequest& req) {
                         return one.template operator()<sim::GetEntityInfoResponse, sim::EntityInfo>(
                             req.entity, [](const World& w, BodyId b) {
                               sim::EntityInfo info;
                               info.category = static_cast<std::uint8_t>(sim::Category::DynamicObject);
                               info.description = "rigid body " + std::to_string(w.body_id(b)) + ": " +
                                                  std::to_string(w.hull(b).size()) +
                                                  " point masses, M = " + std::to_string(w.mass(b)) +
                                                  " kg, I = " + std::to_string(w.inertia(b)) + " kg m^2";
                               return info;
                             });
                       },
                       refuse_malformed<sim::GetEntityInfoResponse>()));
  out.emplace_back("get_entity_state", std::string(sim::GetEntityStateRequest::kService),
                   typed_handler<sim::GetEntityStateRequest, sim::GetEntityStateResponse>(
                       [one](const RequestHeader&, const sim::GetEntityStateRequest& req) {
                         return one.template operator()<sim::GetEntityStateResponse, sim::EntityState>(
                             req.entity, [](const World& w, BodyId b) { return entity_state(w, b); });
                       },
                       refuse_malformed<sim::GetEntityStateResponse>()));
  out.emplace_back("get_entity_bounds", std::string(sim::GetEntityBoundsRequest::kService),
                   typed_handler<sim::GetEntityBoundsRequest, sim::GetEntityBoundsResponse>(
                       [one](const RequestHeader&, const sim::GetEntityBoundsRequest& req) {
                         // TYPE_BOX in the body's own frame: the hull's extent about the centre of
                         // mass at theta = 0, upper right corner first.
                         return one.template operator()<sim::GetEntityBoundsResponse, sim::Bounds>(
                             req.entity, [](const World& w, BodyId b) {
                               Vec2 lo = w.hull(b)[0], hi = lo;
                               for (const Vec2& v : w.hull(b)) {
                                 lo = lo.cwiseMin(v);
                                 hi = hi.cwiseMax(v);
                               }
                               return sim::Bounds{static_cast<std::uint8_t>(sim::BoundsType::Box),
                                                  {planar(hi.x(), hi.y()), planar(lo.x(), lo.y())}};
                             });
                       },
                       refuse_malformed<sim::GetEntityBoundsResponse>()));
  out.emplace_back("set_entity_state", std::string(sim::SetEntityStateRequest::kService),
                   typed_handler<sim::SetEntityStateRequest, sim::SetEntityStateResponse>(
                       [this](const RequestHeader&, const sim::SetEntityStateRequest& req) {
                         return sim::SetEntityStateResponse{set_entity_state(req)};
                       },
                       refuse_malformed<sim::SetEntityStateResponse>()));
}

}  // namespace rbsim::node
