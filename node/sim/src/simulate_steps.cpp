// The SimulateSteps action's executor (simulate_steps.hpp).
#include "simulate_steps.hpp"

#include <algorithm>
#include <chrono>
#include <limits>
#include <mutex>
#include <optional>

#include "rbsim/counts.hpp"
#include "rbsim/simulation_interfaces.hpp"

namespace rbsim::node {

namespace {

namespace sim = msgs::simulation;
using Clock = std::chrono::steady_clock;
using msgs::GoalStatus;

constexpr auto kFeedbackPeriod = std::chrono::milliseconds(50);  // at most 20 feedback messages a second
constexpr double kReadPeriodS = 0.02;                            // progress read about every 20 ms

std::string steps_text(std::int64_t n) {
  return std::to_string(n) + plural(n, " step", " steps");
}

}  // namespace

struct SimulateSteps::State : std::enable_shared_from_this<State> {
  explicit State(control::Controller& c) : controller(c) {}

  struct Goal {
    GoalUuid id{};
    std::int64_t steps = 0;
    std::int64_t start = -1;  // the boundary its `step N` applied at
    bool cancel = false;
    Clock::time_point last_feedback{}, last_read{};
    std::int64_t last_completed = 0;
  };

  control::Controller& controller;
  std::mutex mutex;  // guards server and goal
  ActionServer* server = nullptr;
  std::optional<Goal> goal;  // one goal at a time
  std::unique_ptr<ActionServer> owned;

  // ---- The action server's thread.
  bool on_goal(const GoalUuid& id, std::span<const std::byte> request);
  bool on_cancel(const GoalUuid& id);
  // ---- The run loop's thread (the controller's callbacks).
  void started(const control::CommandResult& r);
  void progress(const World* world, std::int64_t at_step);
  // Both under `mutex`.
  void end(std::int8_t status, std::uint8_t code, std::string message);
  void send_feedback(std::int64_t completed);
  void read_at(std::int64_t step) {
    controller.read([self = shared_from_this(), step](const World* w) { self->progress(w, step); }, step);
  }
};

bool SimulateSteps::State::on_goal(const GoalUuid& id, std::span<const std::byte> request) {
  sim::SimulateStepsSendGoalRequest req;
  if (!msgs::simulation::decode(request, req)) return false;
  if (req.steps == 0 || req.steps > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max()))
    return false;
  // As the definition assumes: only while paused (a running simulation gets no goal).
  if (!controller.settings().paused) return false;
  {
    const std::lock_guard lock(mutex);
    if (goal || server == nullptr) return false;
    goal = Goal{id, static_cast<std::int64_t>(req.steps)};
  }
  control::Command c;
  c.kind = control::CommandKind::Step;
  c.steps = static_cast<std::int64_t>(req.steps);
  c.source = "ros2 action simulate_steps";
  controller.submit(std::move(c),
                    [self = shared_from_this()](const control::CommandResult& r) { self->started(r); });
  return true;
}

bool SimulateSteps::State::on_cancel(const GoalUuid& id) {
  {
    const std::lock_guard lock(mutex);
    if (!goal || goal->id != id) return false;
    if (goal->cancel) return true;
    goal->cancel = true;
  }
  // Stops the stepping at the next boundary; the progress read waiting there then ends the goal.
  control::Command c;
  c.kind = control::CommandKind::StopStepping;
  c.source = "ros2 action simulate_steps cancel";
  controller.submit(std::move(c), [](const control::CommandResult&) {});
  return true;
}

void SimulateSteps::State::started(const control::CommandResult& r) {
  std::int64_t first = 0;
  {
    const std::lock_guard lock(mutex);
    if (!goal) return;
    if (!r.successful) {
      end(GoalStatus::kAborted, sim::Result::kOperationFailed, r.message);
      return;
    }
    goal->start = r.step;
    goal->last_feedback = goal->last_read = Clock::now();
    if (server != nullptr) server->executing(goal->id);
    first = r.step + 1;
  }
  read_at(first);  // outside the mutex: a closed controller calls back at once
}

void SimulateSteps::State::progress(const World* world, std::int64_t at_step) {
  std::int64_t next = 0;
  {
    const std::lock_guard lock(mutex);
    if (!goal) return;
    Goal& g = *goal;
    if (world == nullptr) {
      end(GoalStatus::kAborted, sim::Result::kOperationFailed, "the node ended while stepping");
      return;
    }
    const std::int64_t now = world->step_index();
    const std::int64_t target = g.start + g.steps;
    const std::int64_t completed = std::clamp<std::int64_t>(now - g.start, 0, g.steps);
    const std::string counted = steps_text(completed) + " of " + std::to_string(g.steps);
    if (now >= target) {
      send_feedback(g.steps);
      end(GoalStatus::kSucceeded, sim::Result::kOk,
          "stepped " + steps_text(g.steps) + " from step " + std::to_string(g.start) + " to step " +
              std::to_string(now));
      return;
    }
    if (now < at_step) {  // read early: the loop stopped stepping here
      send_feedback(completed);
      if (now < g.start) {
        end(GoalStatus::kAborted, sim::Result::kOperationFailed,
            "a reset to step " + std::to_string(now) + " ended the stepping (it had run from step " +
                std::to_string(g.start) + ")");
      } else if (g.cancel) {
        end(GoalStatus::kCanceled, sim::Result::kOk,
            "canceled after " + counted + ", paused at step " + std::to_string(now));
      } else {
        end(GoalStatus::kAborted, sim::Result::kOperationFailed,
            "stepping stopped after " + counted + " at step " + std::to_string(now) +
                " (a stop or another node's command came first)");
      }
      return;
    }
    if (!controller.settings().paused) {  // a resume took over: the world runs on
      send_feedback(completed);
      end(GoalStatus::kAborted, sim::Result::kOperationFailed,
          "the simulation was resumed after " + counted + " at step " + std::to_string(now));
      return;
    }
    const auto t = Clock::now();
    if (t - g.last_feedback >= kFeedbackPeriod) {
      send_feedback(completed);
      g.last_feedback = t;
    }
    // The next read about kReadPeriodS of wall time later, at the rate the last stretch stepped.
    const double elapsed = std::chrono::duration<double>(t - g.last_read).count();
    const double done = static_cast<double>(completed - g.last_completed);
    const double stride = elapsed > 0.0 && done > 0.0 ? done * kReadPeriodS / elapsed : 1.0;
    next = now + std::clamp<std::int64_t>(static_cast<std::int64_t>(stride), 1, target - now);
    g.last_read = t;
    g.last_completed = completed;
  }
  read_at(next);
}

void SimulateSteps::State::end(std::int8_t status, std::uint8_t code, std::string message) {
  if (server != nullptr) {
    Bytes out;
    msgs::simulation::encode(
        sim::SimulateStepsGetResultResponse{status, sim::Result{code, std::move(message)}}, out);
    server->finish(goal->id, status, std::move(out));
  }
  goal.reset();
}

void SimulateSteps::State::send_feedback(std::int64_t completed) {
  if (server == nullptr) return;
  Bytes out;
  msgs::simulation::encode(
      sim::SimulateStepsFeedbackMessage{goal->id, static_cast<std::uint64_t>(completed),
                                        static_cast<std::uint64_t>(goal->steps - completed)},
      out);
  server->feedback(std::move(out));
}

// ---------------------------------------------------------------------------------------------
rbsim::Result<std::unique_ptr<SimulateSteps>> SimulateSteps::create(const Participant& participant,
                                                                    const std::string& node,
                                                                    control::Controller& controller) {
  auto state = std::make_shared<State>(controller);
  State* raw = state.get();  // the server's handlers end before the state can (the server goes first)
  ActionServer::Handlers h;
  h.goal = [raw](const GoalUuid& id, std::span<const std::byte> request) {
    return raw->on_goal(id, request);
  };
  h.cancel = [raw](const GoalUuid& id) { return raw->on_cancel(id); };
  h.empty_result = [](std::int8_t status, Bytes& out) {
    msgs::simulation::encode(sim::SimulateStepsGetResultResponse{status, {}}, out);
  };
  auto server = ActionServer::create(participant, node + "/simulate_steps",
                                     sim::SimulateStepsSendGoalRequest::kAction, std::move(h));
  if (!server) return server.error();
  state->owned = std::move(server.value());
  state->server = state->owned.get();
  return std::unique_ptr<SimulateSteps>(new SimulateSteps(std::move(state)));
}

SimulateSteps::~SimulateSteps() {
  std::unique_ptr<ActionServer> server;
  {
    const std::lock_guard lock(state_->mutex);
    state_->server = nullptr;
    server = std::move(state_->owned);
  }
  server.reset();  // joins its thread: no handler runs after this
}

ActionStats SimulateSteps::stats() const {
  const std::lock_guard lock(state_->mutex);
  return state_->server != nullptr ? state_->server->stats() : ActionStats{};
}

}  // namespace rbsim::node
