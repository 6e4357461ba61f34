// The node's services, the ROS 2 way: the six rcl_interfaces parameter services and rbsim's
// controls (pause, resume, reset: std_srvs/srv/Trigger; step: rbsim_msgs/srv/Step; apply_impulse:
// rbsim_msgs/srv/ApplyImpulse), simulation_interfaces' services and rclcpp's get_type_description
// under the node's name, on rmw_cyclonedds_cpp's wire format (rbsim/service.hpp), /parameter_events
// and <node>/commands. Every request becomes a control::Command for
// the run loop (rbsim/control.hpp), answered once it applied at a step boundary; reads answer at once from
// the table as of the last boundary. Requests are served on one thread of this class, woken by any server's
// arrival, so a paused run loop (idling in the controller) still answers. Service introspection (REP 2012,
// rbsim/service_set.hpp) follows the parameter service_configure_introspection: off by default.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "rbsim/control.hpp"
#include "rbsim/middleware.hpp"
#include "rbsim/service.hpp"
#include "rbsim/service_set.hpp"

namespace rbsim::node {

struct NodeServicesOptions {
  std::string node = "/rbsim";  // the node's fully qualified name: services are <node>/<name>
  // How long a request waits for its step boundary before it is answered unsuccessfully (a run
  // that ended, or one stopped by Ctrl-C, answers at once).
  double apply_timeout_s = 10.0;
  // simulation_interfaces' STATE_QUITTING: called once (on the services' thread, after which the
  // reply goes out) to end the node as a SIGINT would, outputs finished, exit 0. Empty: QUITTING
  // answers RESULT_FEATURE_UNSUPPORTED.
  std::function<void()> quit = nullptr;
  // <node>/get_type_description (type_description_interfaces/srv/GetTypeDescription): the
  // description of every type the node's endpoints use (rbsim/node_types.hpp), as rclcpp serves it
  // unless its read-only parameter start_type_description_service is false.
  bool start_type_description_service = true;
  // The folders simulation_interfaces' spawn_entity and spawn_entities read a uri's fragment from,
  // and get_spawnables lists (rbsim node --spawnables DIR): each must be a directory. Empty: a uri
  // is refused and get_spawnables answers RESULT_FEATURE_UNSUPPORTED.
  std::vector<std::string> spawnables = {};
  // The same for load_world's uri and get_available_worlds (rbsim node --worlds DIR, the bundled
  // scenes by default). Empty: a uri is refused and get_available_worlds answers
  // RESULT_FEATURE_UNSUPPORTED; a resource_string still loads.
  std::vector<std::string> worlds = {};
  // REP 2012 introspection of the services from the start (the parameter
  // service_configure_introspection as the run starts; later changes of it turn it on and off).
  IntrospectionState introspection = IntrospectionState::Off;
};

// For the end line.
struct NodeServiceCounters {
  std::uint64_t received = 0;        // requests taken from DDS
  std::uint64_t calls = 0;           // requests answered
  std::uint64_t dropped = 0;         // not answered: queue full, too large, malformed, client gone
  std::uint64_t events = 0;          // /parameter_events published
  std::uint64_t commands = 0;        // /<ns>/commands published
  std::uint64_t service_events = 0;  // <service>/_service_event published
};

class NodeServices {
 public:
  // Creates the servers and starts serving. `controller` outlives this object.
  static Result<std::unique_ptr<NodeServices>> create(const Participant& participant,
                                                      control::Controller& controller,
                                                      const NodeServicesOptions& options);
  ~NodeServices();  // stops serving (a request in flight is answered first)
  NodeServices(const NodeServices&) = delete;
  NodeServices& operator=(const NodeServices&) = delete;

  // The controller's observer (Controller::on_command): publishes every command with its outcome
  // on <node>/commands (rbsim_msgs/msg/Command, numbered from 0 without gaps; reliable, transient
  // local, keep all) and /parameter_events for every parameter a command changed, and turns
  // service introspection on or off when service_configure_introspection changed (its publishers
  // made or destroyed there: at that boundary only). Called on the run loop's thread.
  void command_applied(const control::Command& command, const control::CommandResult& result);
  // The rbsim_msgs/msg/Command command_applied() published last (the run loop's thread), for the
  // node's other outputs of /<ns>/commands (its Foxglove server).
  std::span<const std::byte> last_command() const;
  NodeServiceCounters counters() const;
  // The node's services as create() serves them, in that order: name under the node ("pause") and
  // type ("std_srvs/srv/Trigger"), for `rbsim record --services` to find an event topic's type.
  struct Served {
    std::string name, type;
  };
  static std::vector<Served> catalogue();
  // simulation_interfaces' services, the part of catalogue() the node's other front ends offer too
  // (its Foxglove server, and rbsim bridge's, which forwards them to the node's DDS services).
  static std::vector<Served> simulation_catalogue();
  // Those services as create() serves them, the very handlers DDS calls (one implementation of
  // each): a handler takes a request's CDR and writes its reply's, blocking until the answer is
  // ready (step_simulation until its steps are done; every wait bounded by apply_timeout_s, plus
  // the steps' pace). The commands a call submits are recorded with `source` ("foxglove") where
  // DDS's say "ros2 service". Callable from any thread while this object lives.
  struct Handled {
    std::string name, type;
    ServiceServer::Handler handler;
  };
  std::vector<Handled> simulation_handlers(std::string source) const;

  struct Impl;  // node_services.cpp

 private:
  explicit NodeServices(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace rbsim::node
