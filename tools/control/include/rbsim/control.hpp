// Control of a running scene: commands as data, applied at step boundaries.
//
// Every control input, from any source (a ROS 2 service, Foxglove, a script), is one Command: the
// step at which it applies, what it is, its arguments and where it came from. A Controller queues
// commands from any thread and applies them on the run loop's thread at step boundaries (the
// Driver's StepHook, rbsim/run.hpp), never inside a step, and delivers each result (success, a
// message, the step at which it applied) through a future or a callback. While paused the run
// loop idles in the controller, still answering commands and stop requests (bounded waits).
//
// Determinism: a change applied at the boundary of step k acts on the steps from k on exactly as
// if the world had been made with it there; a run with no commands steps exactly as a run without
// a controller; pauses change wall time only.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <future>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "rbsim/core.hpp"
#include "rbsim/parameters.hpp"
#include "rbsim/run.hpp"
#include "rbsim/scene.hpp"

namespace rbsim::control {

// StopStepping ends a `step N` in progress at its boundary, the run staying paused there (the
// SimulateSteps action's cancel; a Pause leaves the stepping alone); not stepping, it does nothing.
// Spawn, Delete and ResetSpawned change the world's structure (simulation_interfaces' SpawnEntity,
// DeleteEntity and ResetSimulation with SCOPE_SPAWNED); see SpawnArgs. LoadWorld and UnloadWorld
// replace the world (simulation_interfaces' LoadWorld, UnloadWorld); see WorldArgs.
enum class CommandKind : std::uint8_t {
  SetParameters,
  Pause,
  Resume,
  Step,
  Reset,
  Impulse,
  SetState,
  StopStepping,
  Spawn,
  Delete,
  ResetSpawned,
  LoadWorld,
  UnloadWorld
};
// "set_parameters", "pause", "resume", "step", "reset", "apply_impulse", "set_entity_state",
// "stop_stepping", "spawn_entity", "delete_entity", "reset_spawned", "load_world", "unload_world"
const char* to_string(CommandKind kind);
// Spawn, Delete, ResetSpawned, LoadWorld or UnloadWorld: the kinds only a run whose outputs follow
// may apply.
constexpr bool changes_structure(CommandKind kind) {
  return kind == CommandKind::Spawn || kind == CommandKind::Delete || kind == CommandKind::ResetSpawned ||
         kind == CommandKind::LoadWorld || kind == CommandKind::UnloadWorld;
}

// A linear impulse J (N s, world axes) at the point p (m, body frame, relative to the centre of
// mass) of body `body`: V += J / M, omega += ((R(theta) p) x J) / I (World::apply_impulse).
struct ImpulseArgs {
  std::int64_t body = 0;  // as received: checked against the body count when applied
  Vec2 impulse{0.0, 0.0};
  Vec2 point{0.0, 0.0};
};

// The state of body `body` set at a step boundary (simulation_interfaces' SetEntityState): its pose
// (centre of mass X in m, world frame; theta in rad, CCW > 0) and/or its velocities (V in m/s,
// omega in rad/s), the rest kept. The forces are not state: the next step computes them afresh.
struct StateArgs {
  std::int64_t body = 0;  // as received: checked against the body count when applied
  bool set_pose = false;
  bool set_twist = false;
  Vec2 position{0.0, 0.0};
  double theta = 0.0;
  Vec2 velocity{0.0, 0.0};
  double omega = 0.0;
};

// A body spawned from a fragment (rbsim/scene.hpp's parse_fragment; its text is what a recording
// keeps, so a re-run needs no file). The body's centre of mass goes to `position` with theta =
// `theta` (the fragment's own frame rotated by theta), moving with the fragment's velocity and
// spin as written (world axes); its springs join it to the bodies they name. The name is `name`
// when given and never used before in the session; otherwise, with `allow_renaming` (or when
// empty), the first of name_1, name_2, ... ("entity" when empty) never used before. A name once
// used, even by a deleted body, is never given again.
struct SpawnArgs {
  std::string resource;  // the fragment's XML text
  std::string uri;       // where the text came from, as the request gave it (for messages only)
  std::string name;      // the full name asked for ("ns/name"), checked by the caller's rules
  bool allow_renaming = false;
  Vec2 position{0.0, 0.0};
  double theta = 0.0;
  // The fragment already parsed off the loop's thread (a service's), from `resource`; null: the
  // controller parses `resource` when the command applies (a re-run).
  std::shared_ptr<const Fragment> fragment;
};

// A world loaded in place of the running one: a FOSSSim scene's XML text (what a recording keeps,
// so a re-run needs no file), parsed by parse_scene. The world starts at step 0, paused (ROS 2's
// STATE_STOPPED), its parameters the scene's; the session's ids and used names go on. Unloading
// leaves an empty world that does not step (no world: STATE_NO_WORLD) until a load.
struct WorldArgs {
  std::string resource;  // the scene's XML text
  std::string uri;       // where the text came from, as the request gave it (the world's uri, messages)
  // The scene already parsed off the loop's thread (a service's), from `resource`; null: the
  // controller parses `resource` when the command applies (a re-run).
  std::shared_ptr<const Scene> scene;
};

// The world a Controller steps, as last published: what GetCurrentWorld answers.
struct WorldInfo {
  bool loaded = true;  // false after an unload_world, until a load_world
  std::string name;    // the scene's name (its file stem; a resource string's <scenetag>, else "world")
  std::string uri;     // as loaded ("" for the world the run started with: `path` says)
  std::string path;    // the scene file the run started with, or the uri
  std::string description;
  double dt = 0.0;
  std::uint32_t number = 0;  // worlds loaded before it in the session
};

// LoadWorld or UnloadWorld: a new world, whose steps start again at 0 (only a recording follows).
constexpr bool replaces_world(CommandKind kind) {
  return kind == CommandKind::LoadWorld || kind == CommandKind::UnloadWorld;
}
// Reset, LoadWorld or UnloadWorld: applied, the world starts again at step 0, so the commands
// recorded after it are for the steps of that new start (a re-run's epochs, ScriptedRun).
constexpr bool restarts_steps(CommandKind kind) {
  return kind == CommandKind::Reset || replaces_world(kind);
}

// Why a command was refused, where a caller answers differently (simulation_interfaces' codes).
enum class Refusal : std::uint8_t {
  Other,
  NameTaken,     // spawn: the name is in use or was used, and renaming is not allowed
  NoSuchEntity,  // delete, or a spring naming a body: no body of that name
  BadResource,   // spawn: the fragment does not parse; load_world: the scene does not
  NoWorld,       // unload_world (and the commands that need one) with no world loaded
};

// One control input as data (issue 23 records these as rbsim_msgs/msg/Command).
struct Command {
  static constexpr std::int64_t kNextStep = -1;
  // The step boundary at which it applies (the world at this step, before it steps on), or
  // kNextStep: the next boundary (a live request). A command for a boundary already passed fails.
  std::int64_t step = kNextStep;
  CommandKind kind = CommandKind::Pause;
  std::vector<Parameter> parameters;  // SetParameters
  bool atomic = true;                 // SetParameters: all or nothing (set_parameters_atomically), or
                                      // each its own result (set_parameters)
  std::int64_t steps = 0;             // Step: how many, >= 1; only while paused
  double pause_seconds = 0.0;         // Pause: resume by itself after this much wall time (0: stay
                                      // paused until a Resume); wall time only, never the run
  ImpulseArgs impulse;                // Impulse
  StateArgs state;                    // SetState
  SpawnArgs spawn;                    // Spawn
  std::string entity;                 // Delete: the body's name
  WorldArgs world;                    // LoadWorld
  std::string source;                 // "ros2 service", "foxglove", "script", ...
};

struct CommandResult;
// A command and its outcome as rbsim_msgs/msg/Command (/<ns>/commands, recordings): `sequence` is
// the node's count of commands, `dt` stamps the step in simulated time.
msgs::CommandMessage to_message(const Command& command, const CommandResult& result, std::uint64_t sequence,
                                double dt);
// The command a message records, to apply again at its step (a re-simulation); an unknown kind
// or a body past int64 is an error naming the sequence number.
[[nodiscard]] Result<Command> from_message(const msgs::CommandMessage& message);

struct CommandResult {
  bool successful = false;
  std::string message;
  std::int64_t step = Command::kNextStep;  // the boundary at which it applied (kNextStep: it never did)
  // A step N: the boundary its stepping ends at, where the world stands paused next (`step` plus
  // every step still to take, this command's included); kNextStep for the other commands.
  std::int64_t ends_at = Command::kNextStep;
  // SetParameters: one result for an atomic batch, one per parameter otherwise.
  std::vector<SetParametersResult> results;
  // Every parameter the command changed, with its new value, in table order for a reset (which
  // returns parameters to their initial values) and request order otherwise; `paused` for a pause
  // or resume that changed it. What /parameter_events and Foxglove's parameter updates report.
  std::vector<Parameter> changed;
  // Parameters that came or went with a structural change (a spawned body's springs): what
  /// /parameter_events reports as new and deleted.
  std::vector<Parameter> added;
  std::vector<std::string> removed;
  Refusal refusal = Refusal::Other;           // when not successful
  std::string entity;                         // Spawn: the name given; Delete: the name deleted
  std::int32_t body_id = -1;                  // Spawn, Delete: the body's id (msgs' BodyState.id)
  std::vector<std::int32_t> removed_springs;  // Delete, ResetSpawned: the ids of the springs that went
};

// For the end line: calls answered (commands applied or refused, and reads) and parameters
// changed.
struct ControlCounters {
  std::uint64_t commands = 0;
  std::uint64_t queries = 0;
  std::uint64_t parameter_changes = 0;
};

// What steers a run from outside its loop (the Foxglove server): the run's own Controller, or a
// relay of the same requests to a node over DDS (rbsim bridge, bridge::RemoteSteering). An I/O
// boundary, so an interface. All of it may be called from any thread; submit()'s `done` and the
// observers run on the steering's own thread and must not block.
class Steering {
 public:
  virtual ~Steering() = default;
  // Applies `command` (at its step boundary, or the next one) and reports the outcome.
  virtual void submit(Command command, std::function<void(const CommandResult&)> done) = 0;
  // The parameters as last known: an unknown name gives nullopt or NotSet.
  virtual std::vector<std::optional<ParameterValue>> get(const std::vector<std::string>& names) const = 0;
  virtual std::vector<ParameterType> types(const std::vector<std::string>& names) const = 0;
  // Every parameter's name, in table order.
  virtual std::vector<std::string> names() const = 0;
  // Adds an observer of every command applied or refused (its `changed` parameters above all).
  virtual void on_command(std::function<void(const Command&, const CommandResult&)> observer) = 0;
};

class Controller final : public StepHook, public Steering {
 public:
  // `scene` holds the run's initial parameters (apply_overrides) and outlives the controller:
  // reset goes back to its step 0 (a loaded world's, once one is). `steps` is the pass length (the
  // `steps` parameter; a loaded world's is its scene's, Scene::step_count).
  Controller(const Scene& scene, std::int64_t steps, RunSettings settings);
  ~Controller() override;
  Controller(const Controller&) = delete;
  Controller& operator=(const Controller&) = delete;

  // ---- Any thread.
  // Queues a command; its result arrives once it applied (or was refused) at a boundary, or when
  // the controller closes.
  std::future<CommandResult> submit(Command command);
  // Same; `done` runs on the run loop's thread (or the closing one) and must not block.
  void submit(Command command, std::function<void(const CommandResult&)> done) override;
  // Queues `commands` as one: they reach the run loop together, so those for the next boundary
  // (kNextStep) all apply at that one boundary, in order, with no other command between them
  // (simulation_interfaces' SpawnEntities). One result each, in order.
  std::vector<std::future<CommandResult>> submit_all(std::vector<Command> commands);
  // The body names (spawned bodies' own, "body_<id>" for the scene's), on the loop's thread only:
  // inside a read(). A body's id, or nullopt.
  std::optional<std::int32_t> find_entity(std::string_view name) const;
  std::string entity_name(std::int32_t id) const;
  // Reads as of the last boundary (rcl_interfaces' get, describe, get_types, list). An unknown
  // name gives nullopt or NotSet; rclcpp's services answer an empty list when any name is
  // undeclared. list() keeps the table's order (rclcpp's is alphabetical, from its std::map).
  std::vector<std::optional<ParameterValue>> get(const std::vector<std::string>& names) const override;
  std::vector<std::optional<ParameterDescriptor>> describe(const std::vector<std::string>& names) const;
  std::vector<ParameterType> types(const std::vector<std::string>& names) const override;
  ListParametersResult list(const std::vector<std::string>& prefixes, std::uint64_t depth) const;
  std::vector<std::string> names() const override { return list({}, kDepthRecursive).names; }
  // Runs `reader` on the run loop's thread at the first boundary at or after step `at_step` (0:
  // the next one), after the commands due there, with the world as it stands there; earlier at a
  // boundary where the loop stops stepping (paused with no steps left to take), when the reader
  // sees a world short of `at_step`; with nullptr when the controller closes first. For reads of
  // the world's state (simulation_interfaces' services): the world is the loop's alone, so a
  // reader copies what it needs and must not block. Counted as a query.
  void read(std::function<void(const World*)> reader, std::int64_t at_step = 0);
  RunSettings settings() const;
  ControlCounters counters() const;
  // The world as of the last boundary (simulation_interfaces' GetCurrentWorld, GetSimulationState's
  // STATE_NO_WORLD, the stamps of a world whose dt changed).
  WorldInfo world_info() const;
  // Answers every queued command with failure (`reason`) and refuses later ones at once. A
  // running loop ends its pass as stopped at its next boundary; a paused one is woken to do so.
  void close(const std::string& reason);

  // ---- Set up before the run (not thread-safe against a running loop).
  // Called on the loop's thread whenever rate, publish_every or paused changed (the node's pacer
  // and publishers follow it).
  void on_settings(std::function<void(const RunSettings&)> listener) {
    settings_listener_ = std::move(listener);
  }
  // An offline run (rbsim run --commands): a pause that nothing queued can end (no resume, no
  // step, no timer; nobody else submits) ends the pass there instead of idling for ever.
  void end_when_idle(bool on) { end_when_idle_ = on; }
  // Whether a pass ended that way, and at which step.
  std::optional<std::int64_t> ended_paused() const { return ended_paused_; }
  // Adds an observer, called on the loop's thread for every command applied or refused at a
  // boundary, with its step filled in (the record of commands as data); observers are called in
  // the order they were added (the node's /parameter_events, the Foxglove server's updates).
  void on_command(std::function<void(const Command&, const CommandResult&)> observer) override {
    observers_.push_back(std::move(observer));
  }

  // ---- The run loop's thread (StepHook).
  void start(World& world) override;
  // Spawn, delete and reset_spawned apply only where every output follows (refused otherwise,
  // naming why).
  void outputs_follow_structure(bool yes) override { structure_allowed_ = yes; }
  const Entities* entities() const override { return &entities_; }
  std::int64_t loaded_steps() const override { return steps_; }
  Boundary boundary(World& world, bool (*stop)()) override;

 private:
  struct Pending {
    Command command;
    std::uint64_t sequence = 0;
    std::function<void(const CommandResult&)> done;
  };
  // Queues `pending` in order, under one lock (consecutive sequence numbers).
  void enqueue(std::vector<Pending> pending);
  // Moves the incoming queue into the schedule (step order, then arrival order).
  void take_incoming();
  bool due(std::int64_t step) const;
  // The schedule's first command due at `step` (its size if none); with `defer_live`, none of the
  // live commands (kNextStep) taken after the last change held the loop.
  std::size_t next_due(std::int64_t step, bool defer_live) const;
  CommandResult execute(Command& command, World& world, Boundary& boundary);
  CommandResult set_parameters(const Command& command, World& world, Boundary& boundary);
  CommandResult reset(World& world, Boundary& boundary);
  CommandResult impulse(const Command& command, World& world);
  CommandResult set_state(const Command& command, World& world);
  // The living world (src/living_world.cpp).
  CommandResult spawn(const Command& command, World& world);
  CommandResult remove(const Command& command, World& world);
  CommandResult reset_spawned(World& world);
  // Worlds (src/worlds.cpp): `world` replaced by a scene's (or by none), stopped at its step 0.
  CommandResult load_world(const Command& command, World& world, Boundary& boundary);
  CommandResult unload_world(World& world, Boundary& boundary);
  void replace_world(std::shared_ptr<const Scene> scene, World fresh, std::int64_t steps, World& world,
                     Boundary& boundary, CommandResult& r);
  // A command that needs a world, refused while there is none (after unload_world).
  std::optional<CommandResult> needs_world(const Command& command) const;
  // Removes body `dense` and its springs from the world and from entities_.
  Status remove_dense(World& world, std::int32_t dense, std::vector<std::int32_t>& removed_springs);
  // The session's state after a new world (a reset, a pass's start): ids continued, spawned
  // bodies forgotten (their names stay used).
  void renew(World& world, std::int32_t next_body_id, std::int32_t next_spring_id);
  void follow_structure(const World& world, CommandResult* r);
  void settings_changed(Boundary& boundary);
  // Applies one command now (from the schedule, or a timed pause's own resume): result, counters,
  // observer and callback.
  // Applies `pending` and keeps it with its result in `answered_`; answer() then tells its
  // observers and its caller, after publish_values(), so a read after an answer sees the change.
  void apply_now(Pending& pending, World& world, Boundary& boundary);
  void answer();
  // Runs the reads queued by read() that are due at this boundary (all of them when `idle`: the
  // loop is about to wait for a command).
  void serve_reads(const World& world, bool idle);
  std::vector<std::pair<Pending, CommandResult>> answered_;  // run loop thread only
  void publish_values(const World& world);

  const Scene* scene_;                         // the world's scene: the run's, or loaded_scene_
  std::shared_ptr<const Scene> loaded_scene_;  // the world loaded last (null: none yet)
  std::int64_t steps_;
  WorldInfo world_info_;  // the loop thread's; published_world_ is what readers see

  mutable std::mutex mutex_;  // guards the members down to closed_
  std::condition_variable wake_;
  std::vector<Pending> incoming_;
  struct Read {
    std::int64_t at_step = 0;
    std::function<void(const World*)> reader;
  };
  std::vector<Read> reads_;   // read()
  ParameterTable published_;  // what readers see: the table as of the last boundary
  RunSettings published_settings_;
  WorldInfo published_world_;
  mutable ControlCounters counters_;
  bool closed_ = false;
  std::string close_reason_;
  std::uint64_t next_sequence_ = 0;
  std::atomic<bool> has_incoming_{false};

  // The loop thread's own state.
  ParameterTable table_;
  RunSettings settings_;
  std::vector<Pending> schedule_;  // sorted by (step, sequence); kNextStep first
  std::int64_t step_budget_ = 0;   // steps left of a `step N` while paused
  std::optional<std::chrono::steady_clock::time_point> resume_at_;  // a timed pause's end
  // A running loop's changes of the world's bodies take a bounded share of its time (kChangeShare):
  std::uint64_t taken_sequence_ = 0;  // the newest command taken into the schedule
  std::uint64_t held_sequence_ = 0;   // the newest when a change last held the loop
  std::int64_t change_cpu_ns_ = -1;   // the loop thread's CPU time when that change began (until costed)
  std::int64_t live_from_ns_ = 0;     // monotonic_ns() from which later live commands apply
  std::function<void(const RunSettings&)> settings_listener_;
  std::vector<std::function<void(const Command&, const CommandResult&)>> observers_;
  // Spawned bodies and springs by id, and every name ever given in the session.
  std::map<std::int32_t, std::string> spawned_names_;
  std::map<std::string, std::int32_t, std::less<>> spawned_ids_;
  std::set<std::int32_t> spawned_springs_;
  std::set<std::string, std::less<>> used_names_;
  Entities entities_;                                   // the world's names and colours, in its dense order
  bool structure_edited_ = false;                       // a spawn or delete since the world was made
  std::int32_t next_body_id_ = 0, next_spring_id_ = 0;  // the session's, across worlds
  bool end_when_idle_ = false;
  bool structure_allowed_ = false;
  std::optional<std::int64_t> ended_paused_;
};

// The control services, one mapping from their requests to Commands and from results to their
// replies for every front end (the node's DDS services, the Foxglove server): pause, resume and
// reset (std_srvs/srv/Trigger), step (rbsim_msgs/srv/Step), apply_impulse
// (rbsim_msgs/srv/ApplyImpulse), in that order. A step reply's `step` is the step the world reaches
// when the stepping ends (CommandResult::ends_at; answered as it begins, the published state
// reaches it N steps later), an impulse reply's the boundary it applied at (0 if it never did).
struct ControlService {
  std::string_view name;  // "pause"
  std::string_view type;  // "std_srvs/srv/Trigger"
  CommandKind kind;
};
std::span<const ControlService> control_services();
Command command_for(CommandKind trigger_kind, const msgs::TriggerRequest& request);
Command command_for(const msgs::StepRequest& request);
Command command_for(const msgs::ApplyImpulseRequest& request);
msgs::TriggerResponse trigger_response(const CommandResult& result);
msgs::StepResponse step_response(const CommandResult& result);
msgs::ApplyImpulseResponse impulse_response(const CommandResult& result);

}  // namespace rbsim::control
