// The seam's handles: each forwards to its backend's implementation (rbsim/middleware_backend.hpp).
#include "rbsim/middleware.hpp"

#include "rbsim/assert.hpp"
#include "rbsim/middleware_backend.hpp"

namespace rbsim::node {

std::string NodeName::fully_qualified() const {
  return (ns == "/" ? "" : ns) + "/" + name;
}

// rcl_create_node_logger_name: the namespace without its leading '/', '/' -> '.', then the name.
std::string NodeName::logger_name() const {
  if (ns == "/") return name;
  std::string s = ns.substr(1);
  for (char& c : s) c = c == '/' ? '.' : c;
  return s + "." + name;
}

Participant::Participant(std::unique_ptr<ParticipantImpl> impl) : impl_(std::move(impl)) {}
Participant::Participant(Participant&&) noexcept = default;
Participant::~Participant() = default;
const std::string& Participant::description() const {
  return impl_->description();
}
const NodeName& Participant::node() const {
  return impl_->node();
}

// ---------------------------------------------------------------------------------------------
Result<Publisher> Publisher::create(const Participant& participant, const msgs::TopicSpec& spec,
                                    std::string_view ros_topic, const QosSpec& qos,
                                    const EndpointOptions& options) {
  const TopicRef topic{std::string(ros_topic), std::string(spec.type), &spec};
  auto impl = participant.impl().create_publisher(topic, qos, options);
  if (!impl) return impl.error();
  Publisher pub(std::move(impl.value()), topic.ros_name);
  if (options.in_graph) pub.type_ = NodeTypeCache::register_type(participant.types(), topic.ros_type);
  return pub;
}

Result<Publisher> Publisher::create(const Participant& participant, const RawTopic& raw, const QosSpec& qos,
                                    const EndpointOptions& options) {
  auto impl =
      participant.impl().create_publisher(TopicRef{raw.ros_name, raw.ros_type, nullptr}, qos, options);
  if (!impl) return impl.error();
  Publisher pub(std::move(impl.value()), raw.ros_name);
  if (options.in_graph) pub.type_ = NodeTypeCache::register_type(participant.types(), raw.ros_type);
  return pub;
}

Publisher::Publisher(std::unique_ptr<PublisherImpl> impl, std::string ros_topic)
    : impl_(std::move(impl)), ros_topic_(std::move(ros_topic)) {}
Publisher::Publisher(Publisher&&) noexcept = default;
Publisher::~Publisher() = default;

Status Publisher::publish(std::span<const std::byte> cdr, bool (*stop)()) {
  return impl_->publish(cdr, stop);
}
std::int32_t Publisher::matched() const {
  return impl_->matched();
}
bool Publisher::wait_for_subscribers(std::int32_t count, bool (*stop)()) const {
  return impl_->wait_for_subscribers(count, stop);
}
Status Publisher::flush(double timeout_s, bool (*stop)()) {
  return impl_->flush(timeout_s, stop);
}

// ---------------------------------------------------------------------------------------------
Result<Subscription> Subscription::create(const Participant& participant, const msgs::TopicSpec& spec,
                                          std::string_view ros_topic, const QosSpec& qos,
                                          const EndpointOptions& options) {
  const TopicRef topic{std::string(ros_topic), std::string(spec.type), &spec};
  auto impl = participant.impl().create_subscription(topic, qos, options);
  if (!impl) return impl.error();
  Subscription sub(std::move(impl.value()), topic.ros_name, &spec);
  if (options.in_graph) sub.type_ = NodeTypeCache::register_type(participant.types(), topic.ros_type);
  return sub;
}

Result<Subscription> Subscription::create(const Participant& participant, const RawTopic& raw,
                                          const QosSpec& qos, const EndpointOptions& options) {
  auto impl =
      participant.impl().create_subscription(TopicRef{raw.ros_name, raw.ros_type, nullptr}, qos, options);
  if (!impl) return impl.error();
  Subscription sub(std::move(impl.value()), raw.ros_name, nullptr);
  if (options.in_graph) sub.type_ = NodeTypeCache::register_type(participant.types(), raw.ros_type);
  return sub;
}

Subscription::Subscription(std::unique_ptr<SubscriptionImpl> impl, std::string ros_topic,
                           const msgs::TopicSpec* spec)
    : impl_(std::move(impl)), ros_topic_(std::move(ros_topic)), spec_(spec) {}
Subscription::Subscription(Subscription&&) noexcept = default;
Subscription::~Subscription() = default;

bool Subscription::take(Received& out) {
  return impl_->take(out);
}
std::uint64_t Subscription::lost() const {
  return impl_->lost();
}
std::int32_t Subscription::matched() const {
  return impl_->matched();
}
const msgs::TopicSpec& Subscription::spec() const {
  RBSIM_ASSERT(spec_ != nullptr, "spec() of a Subscription created from a RawTopic");
  return *spec_;
}

// ---------------------------------------------------------------------------------------------
Result<WaitSet> WaitSet::create(const Participant& participant) {
  auto impl = participant.impl().create_waitset();
  if (!impl) return impl.error();
  return WaitSet(std::move(impl.value()));
}
WaitSet::WaitSet() = default;
WaitSet::WaitSet(std::unique_ptr<WaitSetImpl> impl) : impl_(std::move(impl)) {}
WaitSet::WaitSet(WaitSet&&) noexcept = default;
WaitSet& WaitSet::operator=(WaitSet&&) noexcept = default;
WaitSet::~WaitSet() = default;

void WaitSet::attach(const Subscription& subscription) {
  RBSIM_ASSERT(impl_ != nullptr, "attach() to a WaitSet not created");
  impl_->attach(subscription.impl());
}
Result<std::int32_t> WaitSet::wait(std::int64_t timeout_ns) {
  if (impl_ == nullptr) return Error{"wait() on a WaitSet not created"};
  return impl_->wait(timeout_ns);
}

}  // namespace rbsim::node
