// The relay's DDS side: raw CDR samples of every rbsim topic, handed on as they come.
#include "rbsim/relay.hpp"

#include <dds/dds.h>

namespace rbsim::node {

Result<std::unique_ptr<Relay>> Relay::create(const Participant& participant, const std::string& ns) {
  std::unique_ptr<Relay> r(new Relay());
  r->waitset_ = dds_create_waitset(participant.handle());
  if (r->waitset_ < 0)
    return Error{std::string("cannot create a DDS waitset: ") + dds_strretcode(r->waitset_)};
  for (const msgs::TopicSpec& spec : msgs::topics()) {
    QosSpec qos = qos_for(spec);
    if (!qos.transient_local) {
      qos.keep_all = false;
      qos.depth = kDepth;
    }
    auto sub = Subscription::create(participant, spec, msgs::topic_name(spec, ns), qos);
    if (!sub) return sub.error();
    dds_waitset_attach(r->waitset_, sub->reader(), static_cast<dds_attach_t>(r->subscriptions_.size()));
    r->subscriptions_.push_back(std::move(sub.value()));
  }
  return r;
}

Relay::~Relay() {
  if (waitset_ > 0) dds_delete(waitset_);
}

Result<std::uint64_t> Relay::poll(std::int64_t timeout_ns, const OnSample& on_sample) {
  dds_attach_t triggered[16];
  const dds_return_t n = dds_waitset_wait(waitset_, triggered, 16, timeout_ns);
  if (n < 0) return Error{std::string("DDS wait failed: ") + dds_strretcode(n)};
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

}  // namespace rbsim::node
