// simulation_interfaces' SimulateSteps action on the node (<node>/simulate_steps): the executor of
// its goals over the middleware's ActionServer. A goal is accepted only while the simulation is
// paused, with 1 <= steps < 2^63 and no other goal running; it becomes a `step N` Command (recorded
// on <node>/commands like every other input), its progress is read at step boundaries
// (Controller::read, never per step: the reads are spaced to about one per 20 ms of wall time) and
// published as feedback at most every 50 ms and at the end. A cancel becomes a stop_stepping
// Command, so the world stops at the next boundary and the goal ends CANCELED with the steps it
// ran; a reset, a resume or a pause elsewhere that cuts the stepping short ends it ABORTED, saying
// why; the node ending ends it ABORTED.
#pragma once

#include <memory>
#include <string>

#include "rbsim/action.hpp"
#include "rbsim/control.hpp"

namespace rbsim::node {

class SimulateSteps {
 public:
  // `node` is the node's fully qualified name; the action is <node>/simulate_steps.
  static Result<std::unique_ptr<SimulateSteps>> create(const Participant& participant,
                                                       const std::string& node,
                                                       control::Controller& controller);
  ~SimulateSteps();  // the action server stops; reads still queued in the controller do nothing
  SimulateSteps(const SimulateSteps&) = delete;
  SimulateSteps& operator=(const SimulateSteps&) = delete;

  ActionStats stats() const;

  struct State;  // shared with the controller's callbacks (simulate_steps.cpp)

 private:
  explicit SimulateSteps(std::shared_ptr<State> state) : state_(std::move(state)) {}
  std::shared_ptr<State> state_;
};

}  // namespace rbsim::node
