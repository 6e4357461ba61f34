// Servers of one node served together on one thread (the node's parameter and control services,
// the player's): each created as the node's endpoint (ServiceOptions::in_graph: on the graph, with
// its type hashes where the middleware announces them); the thread wakes on any server's
// arrival, or every 20 ms to retry replies waiting for their client's reader, so whatever the
// caller's loop is doing (a paused run, a paused replay) requests are answered.
#pragma once

#include <condition_variable>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "rbsim/service.hpp"

namespace rbsim::node {

class ServiceSet {
 public:
  ServiceSet() = default;
  ~ServiceSet();  // stop()
  ServiceSet(const ServiceSet&) = delete;
  ServiceSet& operator=(const ServiceSet&) = delete;

  // Adds the server <node>/<name> of `srv_type` ("pkg/srv/Name"), served by `handler` once
  // start() was called. Not after start().
  [[nodiscard]] Status add(const Participant& participant, const std::string& node, std::string_view name,
                           std::string_view srv_type, ServiceServer::Handler handler);
  // Starts the serving thread (handlers run there, `budget` requests per server in turn).
  void start(std::size_t budget = 8);
  // Stops serving (a request being handled is answered first); idempotent.
  void stop();
  // Every server's counters, in the order added (from any thread).
  std::vector<ServiceStats> stats() const;

 private:
  void serve_loop(std::size_t budget);
  std::mutex mutex_;  // guards arrived_ and stopping_
  std::condition_variable wake_;
  bool arrived_ = false, stopping_ = false;
  std::thread thread_;
  std::vector<ServiceServer::Handler> handlers_;
  std::vector<ServiceServer> servers_;  // last: gone (their listeners with them) before the mutex
};

}  // namespace rbsim::node
