// The relay's DDS side: raw CDR samples of every rbsim topic, handed on as they come.
#include "rbsim/relay.hpp"

namespace rbsim::bridge {

using namespace node;

Result<std::unique_ptr<Relay>> Relay::create(const Participant& participant, const std::string& ns) {
  std::unique_ptr<Relay> r(new Relay());
  auto waitset = WaitSet::create(participant);
  if (!waitset) return waitset.error();
  r->waitset_ = std::move(waitset.value());
  for (const msgs::TopicSpec& spec : msgs::topics()) {
    QosSpec qos = qos_for(spec);
    if (!qos.transient_local) {
      qos.keep_all = false;
      qos.depth = kDepth;
    }
    auto sub = Subscription::create(participant, spec, msgs::topic_name(spec, ns), qos);
    if (!sub) return sub.error();
    r->waitset_.attach(sub.value());
    r->subscriptions_.push_back(std::move(sub.value()));
  }
  return r;
}

Relay::~Relay() = default;

Result<std::uint64_t> Relay::poll(std::int64_t timeout_ns, const OnSample& on_sample) {
  if (Result<std::int32_t> n = waitset_.wait(timeout_ns); !n) return n.error();
  std::uint64_t count = 0;
  for (Subscription& s : subscriptions_) {
    while (s.take(sample_)) {
      ++count;
      on_sample(s.spec(), sample_.cdr);
    }
  }
  received_ += count;
  return count;
}

std::uint64_t Relay::lost() const {
  std::uint64_t n = 0;
  for (const Subscription& s : subscriptions_) n += s.lost();
  return n;
}

}  // namespace rbsim::bridge
