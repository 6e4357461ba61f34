// rbsim bridge's generic half of service calls: one of a node's services called with a request's
// raw CDR and answered with the reply's, for a front end that relays calls without decoding them
// (the Foxglove server's hosted services: simulation_interfaces' services, as
// node::NodeServices::simulation_catalogue() lists them). RemoteSteering (rbsim/remote_steering.hpp)
// is the other half: the control services and parameters, as Commands.
#pragma once

#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <string_view>

#include "rbsim/middleware.hpp"
#include "rbsim/service.hpp"

namespace rbsim::bridge {

struct ForwardOptions {
  // As RemoteSteeringOptions: how long a call waits for the node's reply (the node answers a
  // read at its next step boundary, a step_simulation once its steps are done, or after its own
  // 10 s), and for the node's service to match at all.
  double call_timeout_s = 12.0;
  double match_timeout_s = 1.0;
};

class ForwardedService {
 public:
  // A client of <node>/<name>, of type `type` ("simulation_interfaces/srv/StepSimulation"), listed
  // on the ROS 2 graph as the bridge's (as RemoteSteering's are).
  static Result<std::unique_ptr<ForwardedService>> create(const node::Participant& participant,
                                                          std::string_view node, std::string_view name,
                                                          std::string_view type,
                                                          const ForwardOptions& options = {});

  // Sends `request` (a request's CDR) and returns the reply's CDR; calls on one object take turns.
  // Errors, each naming the service: no server matched within match_timeout_s (the node is not
  // running, or serves no such service), no reply within call_timeout_s, a failed send.
  [[nodiscard]] Result<Bytes> call(std::span<const std::byte> request);
  const std::string& service() const { return service_; }

 private:
  ForwardedService(node::ServiceClient client, std::string service, const ForwardOptions& options)
      : client_(std::move(client)), service_(std::move(service)), options_(options) {}

  std::mutex mutex_;  // one call at a time: a reply is matched to the call waiting for it
  node::ServiceClient client_;
  std::string service_;
  ForwardOptions options_;
};

}  // namespace rbsim::bridge
