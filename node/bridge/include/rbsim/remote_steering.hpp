// rbsim bridge's steering half: the node's parameters and control services called as a ROS 2
// client calls them, so another transport (the Foxglove server) steers the node. The relay of its
// topics is rbsim/relay.hpp.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <unordered_map>
#include <vector>

#include "rbsim/control.hpp"
#include "rbsim/middleware.hpp"
#include "rbsim/service.hpp"

namespace rbsim::bridge {

struct RemoteSteeringOptions {
  std::string node = "/rbsim";  // the steered node's fully qualified name: its services are <node>/<name>
  // How long a call waits for the node's reply (the node answers once the command applied at a
  // step boundary, or after its own 10 s), and for the node's services to match at all.
  double call_timeout_s = 12.0;
  double match_timeout_s = 1.0;
};

// Steers a node over DDS as any ROS 2 client would: a Command becomes a call of the node's
// services (set_parameters, or set_parameters_atomically for an atomic batch; pause, resume,
// reset, step, apply_impulse), sent from this object's thread in submission order without waiting
// for the previous reply (the node holds an impulse while paused until a step, which must reach
// it), and the reply becomes the CommandResult. Calls on different services may reach the node's
// boundary in either order, as any ROS 2 client's do. The parameter table is the node's (refresh():
// list_parameters and get_parameters), kept current by its /parameter_events, each of which also reaches the
// observers (on_command) as a result whose `changed` lists the event's parameters. What a ROS 2
// service cannot say is refused with a reason: a command for a given step (a service applies at
// the next one) and a timed pause. The node records what it applied with source "ros2 service".
class RemoteSteering final : public control::Steering {
 public:
  static Result<std::unique_ptr<RemoteSteering>> create(const node::Participant& participant,
                                                        const RemoteSteeringOptions& options);
  ~RemoteSteering() override;  // queued commands are answered as failed
  RemoteSteering(const RemoteSteering&) = delete;
  RemoteSteering& operator=(const RemoteSteering&) = delete;

  // Reads the node's parameter table (blocking: at most match_timeout_s for the node's services
  // to match, then call_timeout_s per call). On an error the table is left as it was.
  [[nodiscard]] Status refresh();

  void submit(control::Command command, std::function<void(const control::CommandResult&)> done) override;
  std::vector<std::optional<msgs::ParameterValue>> get(const std::vector<std::string>& names) const override;
  std::vector<msgs::ParameterType> types(const std::vector<std::string>& names) const override;
  std::vector<std::string> names() const override;
  // Set up before submitting (not thread-safe against the running thread's calls).
  void on_command(
      std::function<void(const control::Command&, const control::CommandResult&)> observer) override;

  std::uint64_t calls() const;  // commands relayed (answered by the node or not)

 private:
  struct Pending {
    control::Command command;
    std::function<void(const control::CommandResult&)> done;
  };
  struct InFlight {  // a call sent, its reply awaited
    control::Command command;
    std::function<void(const control::CommandResult&)> done;
    std::size_t client = 0;
    std::int64_t seq = 0;
    std::chrono::steady_clock::time_point deadline;
  };
  RemoteSteering() = default;
  void run();
  void send(Pending pending, std::vector<InFlight>& out);
  void collect(std::vector<InFlight>& out, Bytes& reply);
  void take_events();
  node::ServiceClient& client(std::size_t index) { return clients_[index]; }

  RemoteSteeringOptions options_;
  std::vector<node::ServiceClient> clients_;  // list, get, set, set atomically, then control_services()
  std::optional<node::Subscription> events_;  // /parameter_events
  node::Received event_sample_;
  // Added from any thread (on_command), called on the run thread: guarded by its own mutex, held
  // while they run (an observer must not add another).
  std::mutex observers_mutex_;
  std::vector<std::function<void(const control::Command&, const control::CommandResult&)>> observers_;

  mutable std::mutex mutex_;  // guards everything below
  std::condition_variable wake_;
  std::deque<Pending> queue_;
  bool stopping_ = false;
  std::vector<std::string> names_;
  std::unordered_map<std::string, msgs::ParameterValue> values_;
  std::uint64_t calls_ = 0;
  std::thread thread_;
};

}  // namespace rbsim::bridge
