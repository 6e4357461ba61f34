// simulation_interfaces' services on the node (the ROS 2 standard simulator interfaces, served
// under the node's name as Gazebo serves them under /gzserver/): simulator features, simulation
// state, reset, stepping, and the entities (every body is one, named body_<i> as its /tf child
// frame without the namespace). State changes go through control::Commands, as the node's own
// services do, so they are recorded on <node>/commands and re-simulated; reads of the world run on
// the loop's thread at a step boundary (Controller::read).
#pragma once

#include <atomic>
#include <functional>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "rbsim/control.hpp"
#include "rbsim/service.hpp"
#include "rbsim/simulation_interfaces.hpp"

namespace rbsim::node {

class SimulationServices {
 public:
  using Apply = std::function<control::CommandResult(control::Command)>;
  // `apply` submits a command and waits (bounded) for its result, as NodeServices does for its own
  // services; reads wait up to `timeout_s` for their boundary. `dt`: the scene's step (s).
  // `quit` ends the node (STATE_QUITTING); empty: QUITTING is unsupported.
  SimulationServices(control::Controller& controller, Apply apply, double timeout_s, double dt,
                     std::function<void()> quit = {})
      : controller_(controller),
        apply_(std::move(apply)),
        timeout_s_(timeout_s),
        dt_(dt),
        quit_(std::move(quit)) {}

  // The services, as (name under the node, type, handler).
  using Entry = std::tuple<std::string, std::string, ServiceServer::Handler>;
  void add(std::vector<Entry>& out);

 private:
  control::Controller& controller_;
  Apply apply_;
  double timeout_s_;
  double dt_;
  // STOPPED: set by a stop (and at start), cleared by a play or a pause; the state reads STOPPED
  // while it is set and the world is paused at step 0.
  std::atomic<bool> stopped_{true};
  std::function<void()> quit_;
  std::atomic<bool> quitting_{false};  // QUITTING asked: the state reads QUITTING from then on
  using StateNow = std::function<std::optional<msgs::simulation::State>()>;
  using Run = std::function<control::CommandResult(control::CommandKind)>;
  void add_state(std::vector<Entry>& out);
  msgs::simulation::Result set_state(std::uint8_t target, const StateNow& state_now, const Run& command);
  msgs::simulation::Result step(std::uint64_t steps);
  msgs::simulation::Result set_entity_state(const msgs::simulation::SetEntityStateRequest& req);
  void add_entities(std::vector<Entry>& out);
  void add_entity(std::vector<Entry>& out);
  void add_spawning(std::vector<Entry>& out);
  msgs::simulation::SpawnEntityResponse spawn_entity(const msgs::simulation::SpawnEntityRequest& req);
};

}  // namespace rbsim::node
