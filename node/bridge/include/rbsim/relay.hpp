// rbsim bridge's middleware side: every rbsim topic of one namespace taken as raw CDR, for relaying
// to another transport (the Foxglove server) without decoding. The steering half is
// rbsim/remote_steering.hpp.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "rbsim/middleware.hpp"

namespace rbsim::bridge {

// Subscribes to every topic of msgs::topics() under `ns`: the latched scene description with a
// transient-local reader (a relay started after the node still gets it), the per-step topics with
// keep-last readers, so a relay that falls behind loses its oldest samples instead of slowing the
// node down (a keep-all reader would hold the node's keep-all writers back).
class Relay {
 public:
  static constexpr std::int32_t kDepth = 256;  // per-step samples a reader keeps

  static Result<std::unique_ptr<Relay>> create(const node::Participant& participant, const std::string& ns);
  ~Relay();
  Relay(const Relay&) = delete;
  Relay& operator=(const Relay&) = delete;

  using OnSample = std::function<void(const msgs::TopicSpec& spec, std::span<const std::byte> cdr)>;
  // Waits up to `timeout_ns` for samples and hands every one available to `on_sample`; returns how
  // many there were.
  Result<std::uint64_t> poll(std::int64_t timeout_ns, const OnSample& on_sample);
  std::uint64_t received() const { return received_; }
  std::uint64_t lost() const;  // reported by DDS (rejected, lost)

 private:
  Relay() = default;
  std::vector<node::Subscription> subscriptions_;
  node::WaitSet waitset_;
  node::Received sample_;
  std::uint64_t received_ = 0;
};

}  // namespace rbsim::bridge
