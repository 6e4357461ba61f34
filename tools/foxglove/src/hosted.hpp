// The hosted services' calls (ServerOptions::hosted_services: rbsim replay's player, rbsim node's
// simulation_interfaces services, rbsim bridge's forwards of them), served one at
// a time on a thread of their own, so a handler may block (a seek waits for the player) without
// holding up the server's I/O thread. Each call's answer, a serviceCallResponse frame or a
// serviceCallFailure, goes to `answer` from that thread. The handlers take and give CDR; a call in
// json is converted by the service's schemas (msgs::MessageDecoder's from_json for the request,
// to_json for the response, decoders built once here) and answered in json, as Foxglove wants the
// reply in the request's encoding.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "rbsim/foxglove.hpp"
#include "rbsim/msgs.hpp"

namespace rbsim::foxglove::detail {

class HostedCalls {
 public:
  // A frame for the client `connection` that made the call: binary (the response) or text.
  using Answer = std::function<void(std::uint64_t connection, std::string frame, bool binary)>;
  // `services` are offered with ids first_id, first_id + 1, ...; they outlive this.
  HostedCalls(const std::vector<HostedService>& services, ServiceId first_id, Answer answer);
  ~HostedCalls();  // stop()
  HostedCalls(const HostedCalls&) = delete;
  HostedCalls& operator=(const HostedCalls&) = delete;

  // Queues a call of one of the services, in cdr or json (a json request that does not convert is
  // refused on the service thread with the converter's message). The server bounds the calls in
  // flight per client.
  void call(std::uint64_t connection, ServiceCall call);
  // Joins the thread; calls still queued are dropped unanswered (the server is going).
  void stop();

  // Per service, its request's and response's decoders (none when a schema did not parse: json
  // calls of it then fail saying why).
  struct Codecs {
    std::optional<msgs::MessageDecoder> request, response;
    std::string problem;
  };

 private:
  struct Pending {
    std::uint64_t connection = 0;
    ServiceCall call;
  };
  void serve();
  // The request's CDR for the handler: the payload itself, or the json payload converted.
  Result<std::string> request_cdr(const ServiceCall& call) const;
  // The handler's CDR reply in the call's encoding.
  Result<std::string> reply_in(const ServiceCall& call, std::string cdr) const;

  const std::vector<HostedService>& services_;
  const ServiceId first_id_;
  const Answer answer_;
  std::vector<Codecs> codecs_;
  std::mutex mu_;
  std::condition_variable wake_;
  std::deque<Pending> pending_;
  bool stop_ = false;
  std::thread thread_;
};

}  // namespace rbsim::foxglove::detail
