// The run driver: a scene stepped in a World whose state fans out to sinks after every step.
// rbsim run, node, render and plot all simulate through it, so they stop, report progress and
// report a divergence the same way, and any Sink works under any of them.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "rbsim/core.hpp"
#include "rbsim/scene.hpp"
#include "rbsim/sink.hpp"

namespace rbsim {

// The first non-finite value World::find_nonfinite() found, after step `step`.
struct Divergence {
  std::int64_t step = 0;
  std::int32_t body = -1;  // -1 for a scene-wide quantity
  const char* quantity = "";
  Integrator integrator = Integrator::SymplecticEuler;  // the run's, for the hint
};
// "step N: body b x is not finite: the simulation diverged (try a smaller dt ...)": the one
// message every command gives (the symplectic integrator is suggested only to a run that does
// not use it); a command may append what its outputs hold and its own options.
std::string describe_divergence(const Divergence& divergence);

// The run loop's one hook for control (rbsim/control.hpp's Controller is the implementation):
// called on the loop's thread at every step boundary, never inside a step.
class StepHook {
 public:
  virtual ~StepHook() = default;
  // What a boundary did, for the driver to follow.
  struct Boundary {
    bool state_changed = false;      // parameters, velocities or the whole world changed: the
                                     // divergence check's cached bounds are read again
    bool timeline_changed = false;   // resumed, reset or re-paced: every sink's rebase() is called
    bool structure_changed = false;  // bodies or springs came or went (World::add_body, remove_body)
    bool stop = false;               // a stop request arrived while paused: the pass ends (Stopped)
    bool hold = false;               // the structure changed: the sinks follow it (a paused viewer sees the
                                     // change at once), then boundary() is asked again before any step, so
                                     // each change is written on its own
  };
  // A pass starts (Driver::run), on the world it will step.
  virtual void start(World& world) = 0;
  // Told before start(): whether every output of the run follows a world whose bodies and springs
  // change (Sink::follows_structure). A hook that changes them refuses to where they do not.
  virtual void outputs_follow_structure(bool yes) { (void)yes; }
  // The names and colours of the world's bodies and springs as they stand, after a boundary that
  // changed them (Boundary::structure_changed); nullptr from a hook that never does.
  virtual const Entities* entities() const { return nullptr; }
  // After a boundary that loaded a world (Entities::world raised): the loaded world's pass length,
  // which the pass runs to from then on (its step 0 is the world's).
  virtual std::int64_t loaded_steps() const { return 0; }
  // Before `world` takes its next step. May change the world between steps (a parameter, an
  // impulse, a reset to step 0) and may block while the run is paused, in bounded waits that
  // poll `stop` (may be null).
  virtual Boundary boundary(World& world, bool (*stop)()) = 0;
};

struct DriverOptions {
  std::int64_t steps = 0;        // a pass runs from step 0 to step `steps`
  bool allow_nonfinite = false;  // keep stepping and writing through inf/NaN
  // Polled before every step; true ends the pass early (PassEnd::Stopped, not an error). Must be
  // safe to call from the step loop (e.g. read a flag a signal handler raised).
  bool (*stop)() = nullptr;
  // Called after every step's writes with the step index; must not block.
  std::function<void(std::int64_t)> progress;
  // Called before each step's boundary with the world as it stands; may block (rbsim node's
  // Pacer waits there until the next step is due, so what the boundary applies then, a command
  // that arrived meanwhile included, shows in that very step).
  std::function<void(const World&)> pace;
  // Control at step boundaries (pause, step, reset, parameters, impulses); null: none, and the
  // loop is exactly the one without control.
  StepHook* control = nullptr;
};

enum class PassEnd { Done, Stopped, Diverged };

// Drives passes over one scene: begin() then run() for each pass (rbsim node --loop makes
// several), finish() once at the end. The step loop itself does not allocate; sinks may.
class Driver {
 public:
  // Makes the World of `scene` (the error is World::create's). The scene, and the sinks added,
  // must outlive the driver. A world loaded by the hook replaces the scene, for the next passes too.
  static Result<Driver> create(const Scene& scene);

  // Sinks get begin/write/finish in the order added.
  void add(Sink& sink) { sinks_.push_back(&sink); }

  // Starts a pass at step 0: a new World (the first pass uses the one create() made), then
  // begin() on every sink. The first sink error is returned.
  [[nodiscard]] Status begin();
  // Steps until options.steps, a stop request or a divergence; after every step the state is
  // checked (unless allow_nonfinite), written to every sink and reported to progress. A diverged
  // step is not written. A sink error ends the pass at once and is returned: the sinks are then
  // not finished (their unfinished outputs are discarded when they are destroyed).
  [[nodiscard]] Result<PassEnd> run(const DriverOptions& options);
  // finish() on every sink in order, stopping at the first error. Also after a stop or a
  // divergence: every output then holds the steps written so far.
  [[nodiscard]] Status finish();
  // One whole pass for a command that wants only the outputs (render, plot): begin(), run() and
  // finish(). A divergence is an Error with describe_divergence's message, and the sinks are then
  // not finished.
  [[nodiscard]] Status run_pass(const DriverOptions& options);

  const World& world() const { return *world_; }
  std::int64_t steps_done() const { return steps_done_; }       // over all passes
  const Divergence& divergence() const { return divergence_; }  // after PassEnd::Diverged

 private:
  Driver(const Scene& scene, World world);
  const Scene* scene_;
  std::optional<World> world_;
  bool fresh_ = true;  // world_ is at step 0 and no pass has begun with it
  std::vector<Sink*> sinks_;
  std::uint32_t world_number_ = 0;  // Entities::world of the world the pass steps
  std::int64_t steps_done_ = 0;
  Divergence divergence_;
};

}  // namespace rbsim
