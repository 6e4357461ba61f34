// The in-memory backend's network, participants, publishers, subscriptions and wait sets
// (rbsim/memory_middleware.hpp).
#include <algorithm>
#include <chrono>
#include <cstring>

#include "memory_state.hpp"
#include "rbsim/memory_middleware.hpp"
#include "rbsim/time.hpp"

namespace rbsim::node {

namespace memory {

void release_sample(void* sample) {
  auto* s = static_cast<Sample*>(sample);
  if (s->refs.fetch_sub(1, std::memory_order_acq_rel) == 1) delete s;
}

std::uint64_t push_bounded(std::deque<SampleRef>& queue, SampleRef sample, std::size_t limit) {
  queue.push_back(std::move(sample));
  std::uint64_t dropped = 0;
  while (queue.size() > limit) {
    queue.pop_front();
    ++dropped;
  }
  return dropped;
}

std::size_t history_limit(const QosSpec& qos) {
  if (qos.keep_all) return MemoryNetwork::kKeepAllLimit;
  return static_cast<std::size_t>(std::clamp<std::int32_t>(qos.depth, 1, INT32_MAX));
}

namespace {

// Waits on `cv` until `done` holds or `stop` (looked at every 20 ms) turns true; bounded by
// nothing else, as the DDS publisher's wait for subscribers.
template <class Done>
bool wait_until_stopped(std::unique_lock<std::mutex>& lock, std::condition_variable& cv, Done done,
                        bool (*stop)()) {
  while (!done()) {
    if (stop != nullptr && stop()) return false;
    cv.wait_for(lock, std::chrono::milliseconds(20));
  }
  return true;
}

class MemParticipant final : public ParticipantImpl {
 public:
  MemParticipant(Network network, NodeName node) : network_(std::move(network)), node_(std::move(node)) {
    MemoryNetwork::State& s = network_->state();
    const std::lock_guard lock(s.mutex);
    id_ = ++s.next_id;
    s.nodes.push_back({id_, node_, {}});
  }
  ~MemParticipant() override {
    MemoryNetwork::State& s = network_->state();
    const std::lock_guard lock(s.mutex);
    std::erase_if(s.nodes, [&](const ListedNode& n) { return n.id == id_; });
  }
  MemParticipant(const MemParticipant&) = delete;
  MemParticipant& operator=(const MemParticipant&) = delete;

  const std::string& description() const override { return description_; }
  const NodeName& node() const override { return node_; }
  Result<std::unique_ptr<PublisherImpl>> create_publisher(const TopicRef& topic, const QosSpec& qos,
                                                          const EndpointOptions& options) override {
    return std::unique_ptr<PublisherImpl>(new MemPublisher(network_, id_, topic, qos, options.in_graph));
  }
  Result<std::unique_ptr<SubscriptionImpl>> create_subscription(const TopicRef& topic, const QosSpec& qos,
                                                                const EndpointOptions& options) override {
    return std::unique_ptr<SubscriptionImpl>(
        new MemSubscription(network_, id_, topic, qos, options.in_graph));
  }
  Result<std::unique_ptr<WaitSetImpl>> create_waitset() override {
    return std::unique_ptr<WaitSetImpl>(new MemWaitSet(network_));
  }
  Result<std::unique_ptr<ServiceServerImpl>> create_server(std::string_view service,
                                                           std::string_view srv_type,
                                                           const ServiceOptions& options) override {
    return make_server(network_, id_, service, srv_type, options);
  }
  Result<std::unique_ptr<ServiceClientImpl>> create_client(std::string_view service,
                                                           std::string_view srv_type,
                                                           const ClientOptions& options) override {
    return make_client(network_, id_, service, srv_type, options);
  }

 private:
  Network network_;
  NodeName node_;
  std::uint64_t id_ = 0;
  std::string description_ = "in-memory network";
};

}  // namespace

// ---------------------------------------------------------------------------------------------
MemPublisher::MemPublisher(Network network, std::uint64_t node, const TopicRef& topic, const QosSpec& qos,
                           bool in_graph)
    : network_(std::move(network)), name_(topic.ros_name), type_(topic.ros_type), qos_(qos) {
  MemoryNetwork::State& s = network_->state();
  const std::lock_guard lock(s.mutex);
  id_ = s.add_endpoint(node, in_graph, {MemoryNetwork::Endpoint::Kind::Publisher, name_, type_});
  std::memcpy(guid_.data(), &node, sizeof node);
  std::memcpy(guid_.data() + 8, &id_, sizeof id_);
  s.publishers.push_back(this);
  s.matched.notify_all();
}

MemPublisher::~MemPublisher() {
  MemoryNetwork::State& s = network_->state();
  const std::lock_guard lock(s.mutex);
  std::erase(s.publishers, this);
  s.remove_endpoint(id_);
  s.matched.notify_all();
}

bool MemPublisher::matches(const MemSubscription& sub) const {
  return sub.name() == name_ && sub.type() == type_ && (qos_.transient_local || !sub.qos().transient_local);
}

std::int32_t MemPublisher::matched_locked() const {
  const auto& subs = network_->state().subscriptions;
  return static_cast<std::int32_t>(
      std::count_if(subs.begin(), subs.end(), [&](const MemSubscription* s) { return matches(*s); }));
}

Status MemPublisher::publish(std::span<const std::byte> cdr, bool (*)()) {
  SampleRef sample(new Sample());
  sample.get()->cdr.assign(cdr.begin(), cdr.end());
  sample.get()->source_time_ns = wall_ns();
  sample.get()->writer = guid_;
  sample.get()->offered = qos_;
  MemoryNetwork::State& s = network_->state();
  const std::lock_guard lock(s.mutex);
  for (MemSubscription* sub : s.subscriptions) {
    if (matches(*sub)) sub->push(sample);
  }
  if (qos_.transient_local) push_bounded(history_, std::move(sample), history_limit(qos_));
  return Ok{};
}

std::int32_t MemPublisher::matched() const {
  const std::lock_guard lock(network_->state().mutex);
  return matched_locked();
}

bool MemPublisher::wait_for_subscribers(std::int32_t count, bool (*stop)()) const {
  MemoryNetwork::State& s = network_->state();
  std::unique_lock lock(s.mutex);
  return wait_until_stopped(
      lock, s.matched, [&] { return matched_locked() >= count; }, stop);
}

// ---------------------------------------------------------------------------------------------
MemSubscription::MemSubscription(Network network, std::uint64_t node, const TopicRef& topic,
                                 const QosSpec& qos, bool in_graph)
    : network_(std::move(network)), name_(topic.ros_name), type_(topic.ros_type), qos_(qos) {
  MemoryNetwork::State& s = network_->state();
  const std::lock_guard lock(s.mutex);
  id_ = s.add_endpoint(node, in_graph, {MemoryNetwork::Endpoint::Kind::Subscription, name_, type_});
  s.subscriptions.push_back(this);
  // A late joiner that asks for durability gets what the matched writers kept.
  if (qos_.transient_local) {
    for (const MemPublisher* p : s.publishers) {
      if (!p->matches(*this)) continue;
      for (const SampleRef& kept : p->history()) push(kept);
    }
  }
  s.matched.notify_all();
}

MemSubscription::~MemSubscription() {
  MemoryNetwork::State& s = network_->state();
  const std::lock_guard lock(s.mutex);
  for (MemWaitSet* w : waitsets_) w->detach(this);
  std::erase(s.subscriptions, this);
  s.remove_endpoint(id_);
  s.matched.notify_all();
}

void MemSubscription::push(const SampleRef& sample) {
  lost_ += push_bounded(queue_, sample, history_limit(qos_));
  for (MemWaitSet* w : waitsets_) w->wake();
}

void MemSubscription::detach(MemWaitSet* w) {
  std::erase(waitsets_, w);
}

bool MemSubscription::take(Received& out) {
  SampleRef sample;
  {
    const std::lock_guard lock(network_->state().mutex);
    if (queue_.empty()) return false;
    sample = std::move(queue_.front());
    queue_.pop_front();
  }
  const Sample& got = *sample.get();
  out.cdr = got.cdr;
  out.source_time_ns = got.source_time_ns;
  out.writer = got.writer;
  out.offered = got.offered;
  out.held = Loan(sample.release(), &release_sample);  // the queue's reference, lent on
  return true;
}

std::uint64_t MemSubscription::lost() const {
  const std::lock_guard lock(network_->state().mutex);
  return lost_;
}

std::int32_t MemSubscription::matched() const {
  const std::lock_guard lock(network_->state().mutex);
  const auto& pubs = network_->state().publishers;
  return static_cast<std::int32_t>(
      std::count_if(pubs.begin(), pubs.end(), [&](const MemPublisher* p) { return p->matches(*this); }));
}

// ---------------------------------------------------------------------------------------------
MemWaitSet::~MemWaitSet() {
  const std::lock_guard lock(network_->state().mutex);
  for (MemSubscription* s : attached_) s->detach(this);
}

void MemWaitSet::attach(SubscriptionImpl& subscription) {
  auto& sub = static_cast<MemSubscription&>(subscription);
  const std::lock_guard lock(network_->state().mutex);
  attached_.push_back(&sub);
  sub.attach(this);
}

std::int32_t MemWaitSet::ready_locked() const {
  return static_cast<std::int32_t>(std::count_if(attached_.begin(), attached_.end(),
                                                 [](const MemSubscription* s) { return s->has_samples(); }));
}

Result<std::int32_t> MemWaitSet::wait(std::int64_t timeout_ns) {
  std::unique_lock lock(network_->state().mutex);
  cv_.wait_for(lock, std::chrono::nanoseconds(std::max<std::int64_t>(timeout_ns, 0)),
               [&] { return ready_locked() > 0; });
  return ready_locked();
}

}  // namespace memory

// ---------------------------------------------------------------------------------------------
std::uint64_t MemoryNetwork::State::add_endpoint(std::uint64_t node, bool in_graph,
                                                 MemoryNetwork::Endpoint endpoint) {
  const std::uint64_t id = ++next_id;
  if (!in_graph) return id;
  for (memory::ListedNode& n : nodes) {
    if (n.id == node) n.endpoints.push_back({id, std::move(endpoint)});
  }
  return id;
}

void MemoryNetwork::State::remove_endpoint(std::uint64_t id) {
  for (memory::ListedNode& n : nodes) {
    std::erase_if(n.endpoints, [&](const memory::ListedEndpoint& e) { return e.id == id; });
  }
}

MemoryNetwork::MemoryNetwork() : state_(std::make_unique<State>()) {}
MemoryNetwork::~MemoryNetwork() = default;

std::vector<MemoryNetwork::Node> MemoryNetwork::graph() const {
  const std::lock_guard lock(state_->mutex);
  std::vector<Node> out;
  for (const memory::ListedNode& n : state_->nodes) {
    Node node{n.name, {}};
    for (const memory::ListedEndpoint& e : n.endpoints) node.endpoints.push_back(e.endpoint);
    out.push_back(std::move(node));
  }
  return out;
}

Result<Participant> create_memory_participant(std::shared_ptr<MemoryNetwork> network, const NodeName& node) {
  if (!network) return Error{"no memory network", ErrorCode::InvalidArgument};
  return Participant(std::make_unique<memory::MemParticipant>(std::move(network), node));
}

}  // namespace rbsim::node
