// Servers of one node on one serving thread (service_set.hpp).
#include "rbsim/service_set.hpp"

#include <chrono>

namespace rbsim::node {

ServiceSet::~ServiceSet() {
  stop();
}

Status ServiceSet::add(const Participant& participant, const std::string& node, std::string_view name,
                       std::string_view srv_type, ServiceServer::Handler handler) {
  ServiceOptions so;
  so.in_graph = true;
  so.on_arrival = [this] {
    {
      const std::lock_guard lock(mutex_);
      arrived_ = true;
    }
    wake_.notify_one();
  };
  Result<ServiceServer> s = ServiceServer::create(participant, node + "/" + std::string(name), srv_type, so);
  if (!s) return s.error();
  servers_.push_back(std::move(s.value()));
  handlers_.push_back(std::move(handler));
  return Ok{};
}

void ServiceSet::start(std::size_t budget) {
  if (!thread_.joinable()) thread_ = std::thread([this, budget] { serve_loop(budget); });
}

void ServiceSet::stop() {
  {
    const std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_one();
  if (thread_.joinable()) thread_.join();
}

std::vector<ServiceStats> ServiceSet::stats() const {
  std::vector<ServiceStats> out;
  for (const ServiceServer& s : servers_) out.push_back(s.stats());
  return out;
}

void ServiceSet::serve_loop(std::size_t budget) {
  while (true) {
    {
      std::unique_lock lock(mutex_);
      // Bounded wait: replies waiting for their client's reader are retried at each serve().
      wake_.wait_for(lock, std::chrono::milliseconds(20), [this] { return arrived_ || stopping_; });
      if (stopping_) return;
      arrived_ = false;
    }
    for (std::size_t k = 0; k < servers_.size(); ++k) servers_[k].serve(handlers_[k], budget);
  }
}

}  // namespace rbsim::node
