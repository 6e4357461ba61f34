// The in-memory network's state and its endpoints (rbsim/memory_middleware.hpp). Everything is
// guarded by State::mutex; each endpoint holds the network, so the order endpoints, participants
// and the network go in does not matter.
#pragma once

#include <array>
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "rbsim/memory_middleware.hpp"
#include "rbsim/middleware_backend.hpp"

namespace rbsim::node::memory {

// One published sample, shared by every queue holding it and lent to takers without a copy.
struct Sample {
  std::atomic<std::uint32_t> refs{1};
  Bytes cdr;
  std::int64_t source_time_ns = 0;
  std::array<std::uint8_t, 16> writer{};
  msgs::OfferedQos offered;
};
void release_sample(void* sample);  // Loan's release: drops one reference

// An owning reference to a Sample.
class SampleRef {
 public:
  SampleRef() = default;
  explicit SampleRef(Sample* s) : s_(s) {}  // adopts one reference
  SampleRef(const SampleRef& o) : s_(o.s_) {
    if (s_ != nullptr) s_->refs.fetch_add(1, std::memory_order_relaxed);
  }
  SampleRef(SampleRef&& o) noexcept : s_(std::exchange(o.s_, nullptr)) {}
  SampleRef& operator=(SampleRef o) noexcept {
    std::swap(s_, o.s_);
    return *this;
  }
  ~SampleRef() {
    if (s_ != nullptr) release_sample(s_);
  }
  Sample* get() const { return s_; }
  Sample* release() { return std::exchange(s_, nullptr); }

 private:
  Sample* s_ = nullptr;
};

// Keeps up to `limit` samples, pushing out the oldest; returns how many were pushed out.
std::uint64_t push_bounded(std::deque<SampleRef>& queue, SampleRef sample, std::size_t limit);
std::size_t history_limit(const QosSpec& qos);  // depth, or kKeepAllLimit for keep all

class MemPublisher;
class MemSubscription;
class MemWaitSet;
class MemServer;
class MemClient;

struct ListedEndpoint {
  std::uint64_t id = 0;
  MemoryNetwork::Endpoint endpoint;
};
struct ListedNode {
  std::uint64_t id = 0;
  NodeName name;
  std::vector<ListedEndpoint> endpoints;
};

}  // namespace rbsim::node::memory

namespace rbsim::node {

struct MemoryNetwork::State {
  mutable std::mutex mutex;
  std::condition_variable matched;  // any endpoint created or gone (wait_for_subscribers, wait_for_server)
  std::uint64_t next_id = 0;
  std::vector<memory::ListedNode> nodes;
  std::vector<memory::MemPublisher*> publishers;
  std::vector<memory::MemSubscription*> subscriptions;
  std::vector<memory::MemServer*> servers;
  std::vector<memory::MemClient*> clients;

  // Under `mutex`: lists an endpoint of participant `node` (when `in_graph`); returns its id.
  std::uint64_t add_endpoint(std::uint64_t node, bool in_graph, MemoryNetwork::Endpoint endpoint);
  void remove_endpoint(std::uint64_t id);
};

}  // namespace rbsim::node

namespace rbsim::node::memory {

using Network = std::shared_ptr<MemoryNetwork>;

class MemPublisher final : public PublisherImpl {
 public:
  MemPublisher(Network network, std::uint64_t node, const TopicRef& topic, const QosSpec& qos, bool in_graph);
  ~MemPublisher() override;
  Status publish(std::span<const std::byte> cdr, bool (*stop)()) override;
  std::int32_t matched() const override;
  bool wait_for_subscribers(std::int32_t count, bool (*stop)()) const override;
  Status flush(double, bool (*)()) override { return Ok{}; }

  // Under the network's mutex.
  bool matches(const MemSubscription& s) const;
  std::int32_t matched_locked() const;
  const std::deque<SampleRef>& history() const { return history_; }
  const std::string& name() const { return name_; }
  const std::string& type() const { return type_; }
  const QosSpec& qos() const { return qos_; }

 private:
  Network network_;
  std::string name_, type_;
  QosSpec qos_;
  std::uint64_t id_ = 0;
  std::array<std::uint8_t, 16> guid_{};
  std::deque<SampleRef> history_;  // transient local: what a late subscription gets
};

class MemSubscription final : public SubscriptionImpl {
 public:
  MemSubscription(Network network, std::uint64_t node, const TopicRef& topic, const QosSpec& qos,
                  bool in_graph);
  ~MemSubscription() override;
  bool take(Received& out) override;
  std::uint64_t lost() const override;
  std::int32_t matched() const override;

  // Under the network's mutex.
  void push(const SampleRef& sample);  // wakes its wait sets
  bool has_samples() const { return !queue_.empty(); }
  void attach(MemWaitSet* w) { waitsets_.push_back(w); }
  void detach(MemWaitSet* w);
  const std::string& name() const { return name_; }
  const std::string& type() const { return type_; }
  const QosSpec& qos() const { return qos_; }

 private:
  Network network_;
  std::string name_, type_;
  QosSpec qos_;
  std::uint64_t id_ = 0;
  std::deque<SampleRef> queue_;
  std::uint64_t lost_ = 0;
  std::vector<MemWaitSet*> waitsets_;
};

class MemWaitSet final : public WaitSetImpl {
 public:
  explicit MemWaitSet(Network network) : network_(std::move(network)) {}
  ~MemWaitSet() override;
  void attach(SubscriptionImpl& subscription) override;
  Result<std::int32_t> wait(std::int64_t timeout_ns) override;

  // Under the network's mutex.
  void wake() { cv_.notify_all(); }
  void detach(MemSubscription* s) { std::erase(attached_, s); }

 private:
  std::int32_t ready_locked() const;
  Network network_;
  std::condition_variable cv_;
  std::vector<MemSubscription*> attached_;
};

// Services (memory_service.cpp).
Result<std::unique_ptr<ServiceServerImpl>> make_server(const Network& network, std::uint64_t node,
                                                       std::string_view service, std::string_view srv_type,
                                                       const ServiceOptions& options);
Result<std::unique_ptr<ServiceClientImpl>> make_client(const Network& network, std::uint64_t node,
                                                       std::string_view service, std::string_view srv_type,
                                                       const ClientOptions& options);

}  // namespace rbsim::node::memory
