// Worlds: the running world replaced by a scene's (simulation_interfaces' LoadWorld) or by none
// (UnloadWorld), at a step boundary, as commands carrying the scene's text.
//
// A loaded world is the scene's World at step 0, paused (STATE_STOPPED: it steps when played), its
// parameters the scene's; what was spawned is gone, the session's ids and used names go on. The
// outputs are told through Entities (world raised, the scene it came with): they describe the new
// world from its step 0, and the driver runs the pass to the loaded scene's length. With no world
// the controller holds an empty world that never steps (paused, stepping refused) until a load.
#include <limits>
#include <memory>
#include <optional>
#include <string>

#include "rbsim/control.hpp"
#include "wording.hpp"

namespace rbsim::control {

namespace {

using detail::at;
using detail::refuse;

// With no world, the pass never ends by its length: the loop idles at the boundary until a load.
constexpr std::int64_t kNoWorldSteps = std::numeric_limits<std::int64_t>::max();

// The parameters of `after` that `before` lacks (added), that it had and `after` lacks (removed),
// and those of both whose value changed (changed): what /parameter_events reports for a new world.
void diff_tables(const ParameterTable& before, const ParameterTable& after, CommandResult& r) {
  for (std::size_t i = 0; i < after.size(); ++i) {
    const Parameter p{after.descriptor(i).name, after.value(i)};
    const std::optional<std::size_t> was = before.find(p.name);
    if (!was) {
      r.added.push_back(p);
    } else if (!(before.value(*was) == p.value)) {
      r.changed.push_back(p);
    }
  }
  for (std::size_t i = 0; i < before.size(); ++i) {
    if (!after.find(before.descriptor(i).name)) r.removed.push_back(before.descriptor(i).name);
  }
}

}  // namespace

std::optional<CommandResult> Controller::needs_world(const Command& command) const {
  if (world_info_.loaded) return std::nullopt;
  bool needs = false;
  switch (command.kind) {
    case CommandKind::Pause:
    case CommandKind::StopStepping:
    case CommandKind::LoadWorld:
      break;
    case CommandKind::SetParameters:
      // Running needs a world; the settings (rate, publish_every) do not.
      for (const Parameter& p : command.parameters) {
        needs |= p.name == "paused" && p.value.type == ParameterType::Bool && !p.value.bool_value;
      }
      break;
    default:
      needs = true;
  }
  if (!needs) return std::nullopt;
  return refuse(Refusal::NoWorld,
                std::string(to_string(command.kind)) + ": no world is loaded (load one first)");
}

CommandResult Controller::load_world(const Command& command, World& world, Boundary& boundary) {
  const std::int64_t now = world.step_index();
  const WorldArgs& a = command.world;
  std::shared_ptr<const Scene> scene = a.scene;
  if (!scene) {
    Result<Scene> parsed = parse_scene(a.resource, a.uri.empty() ? "world.xml" : a.uri);
    if (!parsed) return refuse(Refusal::BadResource, "load_world: " + parsed.error().message);
    scene = std::make_shared<const Scene>(std::move(parsed.value()));
  }
  Result<World> fresh = World::create(scene->world);
  if (!fresh) return refuse(Refusal::BadResource, "load_world: " + fresh.error().message);
  CommandResult r;
  r.successful = true;
  const std::int64_t steps = scene->step_count();
  const std::string name = scene->name;
  world_info_.loaded = true;
  world_info_.uri = a.uri;
  world_info_.path = a.uri;
  replace_world(std::move(scene), std::move(fresh.value()), steps, world, boundary, r);
  r.entity = name;
  r.message = "loaded world '" + name + "' (" + std::to_string(world.body_count()) + " bodies) at " +
              at(now) + ": at step 0, stopped";
  return r;
}

CommandResult Controller::unload_world(World& world, Boundary& boundary) {
  const std::int64_t now = world.step_index();
  // No world: none of bodies, springs or forces, stepping nothing; dt and integrator kept, so the
  // topics' stamps stay those of the session.
  auto empty = std::make_shared<Scene>();
  empty->world.dt = world.dt();
  empty->world.integrator = world.integrator();
  Result<World> fresh = World::create(empty->world);
  if (!fresh) return refuse(Refusal::Other, "unload_world: " + fresh.error().message);
  const std::string was = world_info_.name;
  world_info_.loaded = false;
  world_info_.uri.clear();
  world_info_.path.clear();
  CommandResult r;
  r.successful = true;
  replace_world(std::move(empty), std::move(fresh.value()), kNoWorldSteps, world, boundary, r);
  r.entity = was;
  r.message = "unloaded world '" + was + "' at " + at(now) + ": no world";
  return r;
}

void Controller::replace_world(std::shared_ptr<const Scene> scene, World fresh, std::int64_t steps,
                               World& world, Boundary& boundary, CommandResult& r) {
  const std::int32_t bodies = world.next_body_id(), springs = world.next_spring_id();
  loaded_scene_ = std::move(scene);
  scene_ = loaded_scene_.get();
  steps_ = steps;
  world_info_.name = scene_->name;
  world_info_.description = scene_->description;
  world_info_.dt = scene_->world.dt;
  ++world_info_.number;
  world = std::move(fresh);
  renew(world, bodies, springs);  // entities_ the scene's, in world number world_info_.number
  ++entities_.epoch;
  // Stopped at step 0: paused, no stepping or timed resume left.
  step_budget_ = 0;
  resume_at_.reset();
  settings_.paused = true;
  const ParameterTable before = std::move(table_);
  table_ = ParameterTable(*scene_, steps_, settings_);
  follow_structure(world, nullptr);
  table_.refresh(world, settings_);
  diff_tables(before, table_, r);
  settings_changed(boundary);
  boundary.structure_changed = true;
  boundary.state_changed = true;
  boundary.timeline_changed = true;
}

}  // namespace rbsim::control
