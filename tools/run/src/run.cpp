// The run driver shared by rbsim run, node, render and plot.
#include "rbsim/run.hpp"

#include <algorithm>

#include "rbsim/assert.hpp"

namespace rbsim {

std::string describe_divergence(const Divergence& d) {
  const std::string where = d.body >= 0 ? "body " + std::to_string(d.body) + " " : "";
  return "step " + std::to_string(d.step) + ": " + where + d.quantity +
         " is not finite: the simulation diverged (try a smaller dt" +
         (d.integrator == Integrator::ExplicitEuler ? " or the symplectic-euler integrator)" : ")");
}

Driver::Driver(const Scene& scene, World world) : scene_(&scene), world_(std::move(world)) {}

Result<Driver> Driver::create(const Scene& scene) {
  Result<World> created = World::create(scene.world);
  if (!created) return created.error();
  return Driver(scene, std::move(created.value()));
}

Status Driver::begin() {
  if (!fresh_) {
    Result<World> created = World::create(scene_->world);
    if (!created) return created.error();
    world_.emplace(std::move(created.value()));
  }
  fresh_ = false;
  for (Sink* sink : sinks_) {
    if (Status st = sink->begin(*scene_, *world_); !st) return st;
  }
  return Ok{};
}

Result<PassEnd> Driver::run(const DriverOptions& options) {
  World& world = *world_;
  // The divergence check reads only the velocities after each step, against a limit. Positions
  // and angles change only by dt times a velocity (x += dt v: the new v for symplectic Euler, the
  // old one for explicit), so while every |v| stays within the limit, |x| grows by at most
  // dt * limit per step: a running bound (rounding covered by the 1e-12 factor) stands in for a
  // pass over them. Below World::finite_bound() every derived quantity is finite; a velocity past
  // the limit doubles it (one exact pass), and only beyond finite_bound() does the exact search run.
  double bound = world.finite_bound();
  double position = world.peak_position();
  double limit = std::min(bound, std::max(1.0, 2.0 * world.peak_velocity()));
  if (options.control != nullptr) {
    options.control->outputs_follow_structure(std::all_of(
        sinks_.begin(), sinks_.end(), [](const Sink* sink) { return sink->follows_structure(); }));
    options.control->start(world);
  }
  std::int64_t steps = options.steps;
  while (world.step_index() < steps) {
    if (options.pace) options.pace(world);
    if (options.stop != nullptr && options.stop()) return PassEnd::Stopped;
    if (options.control != nullptr) {
      const StepHook::Boundary boundary = options.control->boundary(world, options.stop);
      if (boundary.stop) return PassEnd::Stopped;
      if (boundary.state_changed) {
        // A change between steps breaks the running bound's premise (positions move only by dt
        // times a checked velocity): start it again from the state as it now is.
        bound = world.finite_bound();
        position = world.peak_position();
        limit = std::min(bound, std::max(1.0, 2.0 * world.peak_velocity()));
      }
      if (boundary.structure_changed) {
        const Entities* entities = options.control->entities();
        RBSIM_ASSERT(entities != nullptr, "a hook that changes the structure names what it holds");
        if (entities->world != world_number_) {  // a world loaded: its scene, and its length, from now on
          world_number_ = entities->world;
          if (entities->scene != nullptr) scene_ = entities->scene;
          steps = options.control->loaded_steps();
        }
        for (Sink* sink : sinks_) {
          if (Status st = sink->restructure(world, *entities); !st) return st.error();
        }
      }
      if (boundary.timeline_changed) {
        for (Sink* sink : sinks_) sink->rebase(world);
      }
      if (world.step_index() >= steps) break;
      if (boundary.hold) continue;
    }
    world.step();
    ++steps_done_;
    if (!options.allow_nonfinite) {
      bool exact = !(position <= bound);
      if (!world.velocities_within(limit)) {
        const double v = world.peak_velocity();
        exact |= !(v <= bound);
        if (v <= bound) limit = std::min(bound, 2.0 * v);
      }
      position = (position + world.dt() * limit) * (1.0 + 1e-12);
      if (exact || !(position <= bound)) {
        position = world.peak_position();
        if (const auto bad = world.find_nonfinite()) {
          divergence_ = {world.step_index(), bad->body.index, bad->quantity, world.integrator()};
          return PassEnd::Diverged;
        }
      }
    }
    for (Sink* sink : sinks_) {
      if (Status st = sink->write(world); !st) return st.error();
    }
    if (options.progress) options.progress(world.step_index());
  }
  return PassEnd::Done;
}

Status Driver::run_pass(const DriverOptions& options) {
  if (Status st = begin(); !st) return st;
  const Result<PassEnd> end = run(options);
  if (!end) return end.error();
  if (end.value() == PassEnd::Diverged) return Error{describe_divergence(divergence_)};
  return finish();
}

Status Driver::finish() {
  for (Sink* sink : sinks_) {
    if (Status st = sink->finish(); !st) return st;
  }
  return Ok{};
}

}  // namespace rbsim
