// The Controller: a thread-safe queue of commands drained by the run loop at step boundaries.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <initializer_list>
#include <limits>
#include <memory>
#include <utility>

#include "rbsim/assert.hpp"
#include "rbsim/control.hpp"
#include "rbsim/time.hpp"
#include "wording.hpp"

namespace rbsim::control {

namespace {
// A paused loop wakes at least this often to poll its stop request (Ctrl-C).
constexpr auto kIdleWait = std::chrono::milliseconds(20);
// A running loop spends at most 1 / kChangeShare of its thread's time on changes of the world's
// bodies (a spawn re-publishes the whole scene description and markers): after one, the live
// commands that arrived since wait (kChangeShare - 1) times its cost while the steps go on.
constexpr std::int64_t kChangeShare = 5;

std::int64_t thread_cpu_ns() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

using detail::at;
using detail::failed;

// Whether a state value a command writes (an impulse's result, a set state) keeps every quantity
// the run reports finite: finite, and within World::finite_bound() (0: none computed).
bool reportable(std::initializer_list<double> values, double bound) {
  return std::all_of(values.begin(), values.end(), [bound](double v) {
    return std::isfinite(v) && (bound <= 0.0 || std::abs(v) <= bound);
  });
}
// A command's body: its id (a scene's bodies have their file index), found where it is now.
std::optional<BodyId> find_body(const World& world, std::int64_t id) {
  if (id < 0 || id > std::numeric_limits<std::int32_t>::max()) return std::nullopt;
  return world.find_body_id(static_cast<std::int32_t>(id));
}

std::string bodies_text(const World& world) {
  return "(the world has " + std::to_string(world.body_count()) + " bodies" +
         (world.next_body_id() > world.body_count()
              ? ", ids from 0 to " + std::to_string(world.next_body_id() - 1)
              : std::string()) +
         ")";
}

// A command's `done` that fulfils `future`.
std::function<void(const CommandResult&)> fulfilling(std::future<CommandResult>& future) {
  auto promise = std::make_shared<std::promise<CommandResult>>();
  future = promise->get_future();
  return [promise](const CommandResult& r) { promise->set_value(r); };
}

}  // namespace

const char* to_string(CommandKind kind) {
  switch (kind) {
    case CommandKind::SetParameters:
      return "set_parameters";
    case CommandKind::Pause:
      return "pause";
    case CommandKind::Resume:
      return "resume";
    case CommandKind::Step:
      return "step";
    case CommandKind::Reset:
      return "reset";
    case CommandKind::Impulse:
      return "apply_impulse";
    case CommandKind::SetState:
      return "set_entity_state";
    case CommandKind::StopStepping:
      return "stop_stepping";
    case CommandKind::Spawn:
      return "spawn_entity";
    case CommandKind::Delete:
      return "delete_entity";
    case CommandKind::ResetSpawned:
      return "reset_spawned";
    case CommandKind::LoadWorld:
      return "load_world";
    case CommandKind::UnloadWorld:
      return "unload_world";
  }
  return "?";
}

Controller::Controller(const Scene& scene, std::int64_t steps, RunSettings settings)
    : scene_(&scene),
      steps_(steps),
      published_(scene, steps, settings),
      published_settings_(settings),
      table_(scene, steps, settings),
      settings_(settings) {
  world_info_.name = scene.name;
  world_info_.path = scene.path;
  world_info_.description = scene.description;
  world_info_.dt = scene.world.dt;
  published_world_ = world_info_;
}

Controller::~Controller() {
  close("the run ended");
  for (Pending& p : schedule_) {
    if (p.done) p.done(failed(std::string(to_string(p.command.kind)) + ": " + close_reason_));
  }
}

std::future<CommandResult> Controller::submit(Command command) {
  std::future<CommandResult> future;
  submit(std::move(command), fulfilling(future));
  return future;
}

void Controller::submit(Command command, std::function<void(const CommandResult&)> done) {
  std::vector<Pending> one;
  one.push_back(Pending{std::move(command), 0, std::move(done)});
  enqueue(std::move(one));
}

std::vector<std::future<CommandResult>> Controller::submit_all(std::vector<Command> commands) {
  std::vector<std::future<CommandResult>> futures;
  std::vector<Pending> pending;
  for (Command& c : commands) pending.push_back(Pending{std::move(c), 0, fulfilling(futures.emplace_back())});
  enqueue(std::move(pending));
  return futures;
}

void Controller::enqueue(std::vector<Pending> pending) {
  std::unique_lock lock(mutex_);
  if (closed_) {
    counters_.commands += pending.size();
    const std::string reason = close_reason_;
    lock.unlock();
    for (Pending& p : pending) {
      if (p.done) p.done(failed(std::string(to_string(p.command.kind)) + ": " + reason));
    }
    return;
  }
  for (Pending& p : pending) {
    p.sequence = next_sequence_++;
    incoming_.push_back(std::move(p));
  }
  has_incoming_.store(true, std::memory_order_release);
  wake_.notify_all();
}

void Controller::close(const std::string& reason) {
  std::vector<Pending> refused;
  std::vector<Read> reads;
  {
    const std::lock_guard lock(mutex_);
    if (!closed_) {
      closed_ = true;
      close_reason_ = reason;
    }
    refused.swap(incoming_);
    reads.swap(reads_);
    counters_.commands += refused.size();
    // Takes a running loop off its fast path: its next boundary sees closed_ and stops the pass.
    has_incoming_.store(true, std::memory_order_release);
    wake_.notify_all();
  }
  for (Pending& p : refused) {
    if (p.done) p.done(failed(std::string(to_string(p.command.kind)) + ": " + close_reason_));
  }
  for (Read& r : reads) r.reader(nullptr);
}

void Controller::read(std::function<void(const World*)> reader, std::int64_t at_step) {
  {
    const std::lock_guard lock(mutex_);
    ++counters_.queries;
    if (!closed_) {
      reads_.push_back(Read{at_step, std::move(reader)});
      has_incoming_.store(true, std::memory_order_release);
      wake_.notify_all();
      return;
    }
  }
  reader(nullptr);
}

void Controller::serve_reads(const World& world, bool idle) {
  std::vector<Read> due;
  {
    const std::lock_guard lock(mutex_);
    if (reads_.empty()) return;
    const auto later = [&](const Read& r) { return !idle && r.at_step > world.step_index(); };
    const auto split = std::stable_partition(reads_.begin(), reads_.end(), later);
    due.assign(std::make_move_iterator(split), std::make_move_iterator(reads_.end()));
    reads_.erase(split, reads_.end());
    // A read still waiting for its step keeps the loop off its fast path, so the next boundary
    // looks again.
    if (!reads_.empty()) has_incoming_.store(true, std::memory_order_release);
  }
  for (Read& r : due) r.reader(&world);
}

std::vector<std::optional<ParameterValue>> Controller::get(const std::vector<std::string>& names) const {
  const std::lock_guard lock(mutex_);
  ++counters_.queries;
  std::vector<std::optional<ParameterValue>> values;
  for (const std::string& name : names) {
    const std::optional<std::size_t> i = published_.find(name);
    values.push_back(i ? std::optional(published_.value(*i)) : std::nullopt);
  }
  return values;
}

std::vector<std::optional<ParameterDescriptor>> Controller::describe(
    const std::vector<std::string>& names) const {
  const std::lock_guard lock(mutex_);
  ++counters_.queries;
  std::vector<std::optional<ParameterDescriptor>> out;
  for (const std::string& name : names) {
    const std::optional<std::size_t> i = published_.find(name);
    out.push_back(i ? std::optional(published_.descriptor(*i)) : std::nullopt);
  }
  return out;
}

std::vector<ParameterType> Controller::types(const std::vector<std::string>& names) const {
  const std::lock_guard lock(mutex_);
  ++counters_.queries;
  std::vector<ParameterType> out;
  for (const std::string& name : names) {
    const std::optional<std::size_t> i = published_.find(name);
    out.push_back(i ? published_.descriptor(*i).type : ParameterType::NotSet);
  }
  return out;
}

ListParametersResult Controller::list(const std::vector<std::string>& prefixes, std::uint64_t depth) const {
  const std::lock_guard lock(mutex_);
  ++counters_.queries;
  return published_.list(prefixes, depth);
}

WorldInfo Controller::world_info() const {
  const std::lock_guard lock(mutex_);
  return published_world_;
}

RunSettings Controller::settings() const {
  const std::lock_guard lock(mutex_);
  return published_settings_;
}

ControlCounters Controller::counters() const {
  const std::lock_guard lock(mutex_);
  return counters_;
}

void Controller::publish_values(const World& world) {
  (void)world;
  const std::lock_guard lock(mutex_);
  published_.follow(table_);  // what changed, not a copy of every parameter
  published_settings_ = settings_;
  published_world_ = world_info_;
}

void Controller::start(World& world) {
  // A pass (again, with --loop) starts from the scene: what was spawned in an earlier one is gone,
  // but the session's ids and names go on.
  renew(world, next_body_id_, next_spring_id_);
  change_cpu_ns_ = -1;
  live_from_ns_ = 0;
  follow_structure(world, nullptr);
  table_.refresh(world, settings_);
  publish_values(world);
}

void Controller::take_incoming() {
  std::vector<Pending> arrived;
  {
    const std::lock_guard lock(mutex_);
    arrived.swap(incoming_);
    has_incoming_.store(false, std::memory_order_release);
  }
  for (Pending& p : arrived) {
    taken_sequence_ = std::max(taken_sequence_, p.sequence);
    const auto later = [](const Pending& a, const Pending& b) {
      return a.command.step != b.command.step ? a.command.step < b.command.step : a.sequence < b.sequence;
    };
    schedule_.insert(std::upper_bound(schedule_.begin(), schedule_.end(), p, later), std::move(p));
  }
  RBSIM_ASSERT(std::is_sorted(schedule_.begin(), schedule_.end(),
                              [](const Pending& a, const Pending& b) {
                                return a.command.step != b.command.step ? a.command.step < b.command.step
                                                                        : a.sequence < b.sequence;
                              }),
               "the schedule is in (step, arrival) order");
}

bool Controller::due(std::int64_t step) const {
  return !schedule_.empty() && schedule_.front().command.step <= step;
}

std::size_t Controller::next_due(std::int64_t step, bool defer_live) const {
  for (std::size_t i = 0; i < schedule_.size() && schedule_[i].command.step <= step; ++i) {
    const Pending& p = schedule_[i];
    if (!(defer_live && p.command.step == Command::kNextStep && p.sequence > held_sequence_)) return i;
  }
  return schedule_.size();
}

StepHook::Boundary Controller::boundary(World& world, bool (*stop)()) {
  Boundary b;
  if (change_cpu_ns_ >= 0) {  // a change held the loop: its cost, the sinks' writing included
    live_from_ns_ = monotonic_ns() + (kChangeShare - 1) * (thread_cpu_ns() - change_cpu_ns_);
    change_cpu_ns_ = -1;
  }
  // The common case, a running loop with nothing queued: two loads and a compare.
  if (!has_incoming_.load(std::memory_order_acquire) && !settings_.paused && !due(world.step_index()))
    return b;
  const std::int64_t cpu_start = thread_cpu_ns();
  bool idled = false;
  for (;;) {
    bool applied = false;
    // What a command's `done` submits as it applies (a re-run's next epoch after its reset) is
    // taken at this same boundary: due now, it applies here, before the world steps on.
    // Bodies came or went: the sinks write the changed world before the next command applies, one
    // change at a time, whether the commands came one by one (a paused node) or together (a re-run,
    // a running node), so both write the same messages.
    for (bool more = true; more && !b.structure_changed;) {
      if (has_incoming_.load(std::memory_order_acquire)) take_incoming();
      more = false;
      const bool defer = !settings_.paused && live_from_ns_ > monotonic_ns();
      for (std::size_t i;
           (i = next_due(world.step_index(), defer)) < schedule_.size() && !b.structure_changed;) {
        Pending p = std::move(schedule_[i]);
        schedule_.erase(schedule_.begin() + static_cast<std::ptrdiff_t>(i));
        apply_now(p, world, b);
        applied = more = true;
      }
      more = more && has_incoming_.load(std::memory_order_acquire);
    }
    if (resume_at_ && std::chrono::steady_clock::now() >= *resume_at_) {
      Pending p;
      p.command.kind = CommandKind::Resume;
      p.command.source = "timed pause";
      apply_now(p, world, b);
      applied = true;
    }
    if (applied) {
      publish_values(world);
      answer();
    }
    serve_reads(world, settings_.paused && step_budget_ == 0);
    bool closed = false;
    {
      const std::lock_guard lock(mutex_);
      closed = closed_;
    }
    if (closed) {
      b.stop = true;
      return b;
    }
    // Bodies came or went: the sinks show the change now (while paused, not at the next step), then
    // the driver comes back to this boundary for what else is due.
    if (b.structure_changed) {
      if (!settings_.paused && settings_.rate > 0.0) {  // live commands that arrive from now on wait
        change_cpu_ns_ = cpu_start;
        held_sequence_ = taken_sequence_;
      }
      b.hold = true;
      return b;
    }
    if (!settings_.paused || step_budget_ > 0) break;
    // Offline, nothing can end this pause: no resume timer, nothing due now, and a command queued
    // for a later step is never reached while paused without a step budget.
    if (end_when_idle_ && !due(world.step_index()) && !resume_at_ &&
        !has_incoming_.load(std::memory_order_acquire)) {
      ended_paused_ = world.step_index();
      b.stop = true;
      return b;
    }
    if (stop != nullptr && stop()) {
      b.stop = true;
      return b;
    }
    auto wait = std::chrono::steady_clock::duration(kIdleWait);
    if (resume_at_) wait = std::min(wait, *resume_at_ - std::chrono::steady_clock::now());
    std::unique_lock lock(mutex_);
    wake_.wait_for(lock, wait, [this] { return !incoming_.empty() || !reads_.empty() || closed_; });
    idled = true;
  }
  if (settings_.paused) --step_budget_;  // one step of a `step N`
  RBSIM_ASSERT(step_budget_ >= 0, "a step N never steps more than N");
  // Wall time went on while the loop idled: pacers start afresh from here.
  if (idled) b.timeline_changed = true;
  return b;
}

void Controller::apply_now(Pending& p, World& world, Boundary& b) {
  const std::int64_t now = world.step_index();
  CommandResult r;
  if (p.command.step != Command::kNextStep && p.command.step < now) {
    r = failed(std::string(to_string(p.command.kind)) + ": " + at(p.command.step) + " has passed (now at " +
               at(now) + ")");
  } else {
    r = execute(p.command, world, b);
  }
  r.step = now;
  p.command.step = now;
  {
    const std::lock_guard lock(mutex_);
    ++counters_.commands;
  }
  answered_.emplace_back(std::move(p), std::move(r));
}

void Controller::answer() {
  for (auto& [p, r] : answered_) {
    for (const auto& observer : observers_) observer(p.command, r);
    if (p.done) p.done(r);
  }
  answered_.clear();
}

void Controller::settings_changed(Boundary& boundary) {
  boundary.timeline_changed = true;
  if (settings_listener_) settings_listener_(settings_);
}

// Back to step 0 of the scene as loaded; ids continue (a spawned body's id is never reused).
CommandResult Controller::reset(World& world, Boundary& boundary) {
  const std::int64_t now = world.step_index();
  CommandResult r;
  r.successful = true;
  Result<World> fresh = World::create(scene_->world);
  if (!fresh) return failed("reset: " + fresh.error().message);
  // Bodies spawned or deleted since the world was made: the outputs follow it back.
  const bool edited = structure_edited_;
  const std::int32_t bodies = world.next_body_id(), springs = world.next_spring_id();
  world = std::move(fresh.value());
  renew(world, bodies, springs);
  step_budget_ = 0;
  const ParameterTable before = table_;
  follow_structure(world, &r);
  // Where the outputs follow, the reset is a change they write at once: the world at its step 0
  // again after a scene description (a recording's next segment, rbsim/recording.hpp), edited
  // or not.
  if (edited || structure_allowed_) {
    ++entities_.epoch;
    boundary.structure_changed = true;
  }
  table_.refresh(world, settings_);
  for (std::size_t i = 0; i < table_.size(); ++i) {
    const std::optional<std::size_t> was = before.find(table_.descriptor(i).name);
    if (was && !(table_.value(i) == before.value(*was)))
      r.changed.push_back({table_.descriptor(i).name, table_.value(i)});
  }
  boundary.state_changed = true;
  boundary.timeline_changed = true;
  r.message = "reset at " + at(now) + " to step 0";
  return r;
}

CommandResult Controller::execute(Command& command, World& world, Boundary& boundary) {
  const std::int64_t now = world.step_index();
  CommandResult r;
  r.successful = true;
  if (std::optional<CommandResult> refused = needs_world(command)) return *refused;
  switch (command.kind) {
    case CommandKind::SetParameters:
      return set_parameters(command, world, boundary);
    case CommandKind::Pause:
      r.message = settings_.paused ? "already paused at " + at(now) : "paused at " + at(now);
      resume_at_.reset();
      if (command.pause_seconds > 0.0) {
        resume_at_ = std::chrono::steady_clock::now() +
                     std::chrono::nanoseconds(seconds_to_ns_clamped(command.pause_seconds));
        r.message += " for " + to_string(ParameterValue::of_double(command.pause_seconds)) + " s";
      }
      if (!settings_.paused) {
        settings_.paused = true;
        table_.store(*table_.find("paused"), ParameterValue::of_bool(true));
        r.changed.push_back({"paused", ParameterValue::of_bool(true)});
        settings_changed(boundary);
      }
      return r;
    case CommandKind::Resume:
      r.message = settings_.paused ? "resumed at " + at(now) : "already running at " + at(now);
      step_budget_ = 0;
      resume_at_.reset();
      if (settings_.paused) {
        settings_.paused = false;
        table_.store(*table_.find("paused"), ParameterValue::of_bool(false));
        r.changed.push_back({"paused", ParameterValue::of_bool(false)});
        settings_changed(boundary);
      }
      return r;
    case CommandKind::Step:
      if (!settings_.paused) return failed("step: only while paused (running at " + at(now) + ")");
      if (command.steps < 1)
        return failed("step: steps must be >= 1 (got " + std::to_string(command.steps) + ")");
      if (command.steps > steps_ - now - step_budget_) {
        return failed("step: " + std::to_string(command.steps) +
                      " steps would go past the run's last step (" + at(steps_) + ", now at " + at(now) +
                      (step_budget_ > 0 ? ", already stepping" : "") + ")");
      }
      step_budget_ += command.steps;
      r.ends_at = now + step_budget_;
      r.message = "stepping from " + at(now) + " to " + at(now + step_budget_) + ", then paused";
      return r;
    case CommandKind::Reset:
      return reset(world, boundary);
    case CommandKind::Impulse: {
      CommandResult applied = impulse(command, world);
      boundary.state_changed |= applied.successful;
      return applied;
    }
    case CommandKind::StopStepping:
      r.message = step_budget_ > 0 ? "stopped stepping at " + at(now) + " with " +
                                         std::to_string(step_budget_) + " steps left, paused"
                                   : "not stepping at " + at(now);
      step_budget_ = 0;
      return r;
    case CommandKind::SetState: {
      CommandResult applied = set_state(command, world);
      boundary.state_changed |= applied.successful;
      return applied;
    }
    case CommandKind::Spawn:
    case CommandKind::Delete:
    case CommandKind::ResetSpawned:
    case CommandKind::LoadWorld:
    case CommandKind::UnloadWorld: {
      if (!structure_allowed_) {
        return failed(std::string(to_string(command.kind)) +
                      ": this run's outputs cannot follow a world whose bodies change");
      }
      const std::uint32_t epoch = entities_.epoch;
      CommandResult applied = command.kind == CommandKind::Spawn       ? spawn(command, world)
                              : command.kind == CommandKind::Delete    ? remove(command, world)
                              : command.kind == CommandKind::LoadWorld ? load_world(command, world, boundary)
                              : command.kind == CommandKind::UnloadWorld ? unload_world(world, boundary)
                                                                         : reset_spawned(world);
      boundary.state_changed |= applied.successful;
      boundary.structure_changed |= entities_.epoch != epoch;
      return applied;
    }
  }
  return failed("unknown command");
}

CommandResult Controller::set_parameters(const Command& command, World& world, Boundary& boundary) {
  CommandResult r;
  std::vector<SetParametersResult> checks;
  for (const Parameter& p : command.parameters) checks.push_back(table_.check(p));
  if (command.atomic) {
    const auto bad = std::find_if(checks.begin(), checks.end(), [](const auto& c) { return !c.successful; });
    if (bad != checks.end()) {
      r.results = {*bad};
      r.message = bad->reason;
      return r;  // nothing of the batch changes
    }
  }
  bool settings = false;
  std::size_t changed = 0;
  for (std::size_t k = 0; k < command.parameters.size(); ++k) {
    if (!checks[k].successful) continue;
    const Parameter& p = command.parameters[k];
    const std::size_t i = *table_.find(p.name);
    const ParameterTarget t = table_.target(i);
    if (is_setting(t)) {
      apply(t, p.value, settings_);
      if (t.kind == ParameterTarget::Kind::Paused) {
        resume_at_.reset();
        if (!p.value.bool_value) step_budget_ = 0;
      }
      settings = true;
    } else {
      const Status st = apply(t, p.value, world);
      RBSIM_ASSERT(st.ok(), "a parameter the table accepted was refused by the world");
      boundary.state_changed = true;
    }
    table_.store(i, p.value);
    r.changed.push_back(p);
    ++changed;
  }
  if (settings) settings_changed(boundary);
  {
    const std::lock_guard lock(mutex_);
    counters_.parameter_changes += changed;
  }
  r.successful = changed == command.parameters.size();
  if (command.atomic) {
    r.results = {SetParametersResult{true, {}}};
  } else {
    r.results = std::move(checks);
  }
  r.message = "set " + std::to_string(changed) + " of " + std::to_string(command.parameters.size()) +
              " parameters at " + at(world.step_index());
  for (const SetParametersResult& c : r.results) {
    if (!c.successful) r.message += "; " + c.reason;
  }
  return r;
}

CommandResult Controller::impulse(const Command& command, World& world) {
  const ImpulseArgs& a = command.impulse;
  const std::int64_t now = world.step_index();
  const std::optional<BodyId> found = find_body(world, a.body);
  if (!found) return failed("apply_impulse: no body " + std::to_string(a.body) + " " + bodies_text(world));
  for (double v : {a.impulse.x(), a.impulse.y(), a.point.x(), a.point.y()}) {
    if (!std::isfinite(v)) return failed("apply_impulse: the impulse and its point must be finite");
  }
  const BodyId body = *found;
  const BodyState before = world.state(body);
  if (Status st = world.apply_impulse(body, a.impulse, a.point); !st) {
    return failed("apply_impulse: " + st.error().message);
  }
  // A finite impulse can still be too large: refuse one that takes a velocity past the bound
  // under which every quantity the run reports stays finite, restoring the state exactly.
  const BodyState after = world.state(body);
  if (!reportable({after.velocity.x(), after.velocity.y(), after.omega}, world.finite_bound())) {
    world.set_state(body, before);
    return failed("apply_impulse: too large: body " + std::to_string(a.body) +
                  "'s velocity would leave the range the run can report");
  }
  CommandResult r;
  r.successful = true;
  r.message = "impulse applied to body " + std::to_string(a.body) + " at " + at(now);
  return r;
}

CommandResult Controller::set_state(const Command& command, World& world) {
  const StateArgs& a = command.state;
  const std::optional<BodyId> found = find_body(world, a.body);
  if (!found) return failed("set_entity_state: no body " + std::to_string(a.body) + " " + bodies_text(world));
  if (!a.set_pose && !a.set_twist) return failed("set_entity_state: neither the pose nor the twist is set");
  if (!reportable({a.position.x(), a.position.y(), a.theta, a.velocity.x(), a.velocity.y(), a.omega},
                  world.finite_bound())) {
    return failed("set_entity_state: body " + std::to_string(a.body) +
                  ": every value must be finite and within the range the run can report");
  }
  const BodyId body = *found;
  BodyState s = world.state(body);
  if (a.set_pose) {
    s.position = a.position;
    s.theta = a.theta;
  }
  if (a.set_twist) {
    s.velocity = a.velocity;
    s.omega = a.omega;
  }
  world.set_state(body, s);
  CommandResult r;
  r.successful = true;
  r.message = std::string("set body ") + std::to_string(a.body) + "'s " +
              (a.set_pose && a.set_twist ? "pose and twist"
               : a.set_pose              ? "pose"
                                         : "twist") +
              " at " + at(world.step_index());
  return r;
}

}  // namespace rbsim::control
