// Who may connect (ServerOptions' token, failure limit and client limit), decided on the I/O
// thread before the WebSocket upgrade; no I/O here, so the rules are tested without sockets.
#pragma once

#include <chrono>
#include <cstddef>
#include <deque>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>

#include "rbsim/foxglove.hpp"
#include "transport.hpp"

namespace rbsim::foxglove::detail {

// The token a handshake presents: `Authorization: Bearer T`, else the query's token=T
// (percent-decoded); nullopt when neither is there.
std::optional<std::string> presented_token(std::string_view resource, std::string_view authorization);
// Equal, in a time that depends on neither value (SHA-256 of both, compared with CRYPTO_memcmp).
bool same_token(std::string_view a, std::string_view b);

class AccessGate {
 public:
  using Clock = std::chrono::steady_clock;
  enum class Verdict { Admit, Unauthorized, RateLimited, Full };

  explicit AccessGate(const ServerOptions& options);
  // `admitted`: the connections admitted and not closed yet.
  Verdict check(const std::string& remote, std::string_view resource, std::string_view authorization,
                std::size_t admitted, Clock::time_point now);

 private:
  void forget_old(Clock::time_point now);

  std::string token_;
  std::size_t failures_max_;
  Clock::duration window_;
  std::size_t max_clients_;
  // Per remote address, its latest failures (at most failures_max_) within the window.
  std::unordered_map<std::string, std::deque<Clock::time_point>> failures_;
};

// The transport's admission handler over an AccessGate of `options`: each refusal's status and
// a body saying why, and `counted(verdict)` for each refusal (on the I/O thread).
std::function<Admission(const Handshake&)> admission(const ServerOptions& options,
                                                     std::function<void(AccessGate::Verdict)> counted);

}  // namespace rbsim::foxglove::detail
