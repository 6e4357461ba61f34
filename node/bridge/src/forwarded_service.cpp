// A node's service called with raw CDR (rbsim/forwarded_service.hpp).
#include "rbsim/forwarded_service.hpp"

#include <cstdio>

namespace rbsim::bridge {

namespace {
std::string seconds(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g s", s);
  return buf;
}
}  // namespace

Result<std::unique_ptr<ForwardedService>> ForwardedService::create(const node::Participant& participant,
                                                                   std::string_view node,
                                                                   std::string_view name,
                                                                   std::string_view type,
                                                                   const ForwardOptions& options) {
  std::string service = std::string(node) + "/" + std::string(name);
  node::ClientOptions co;
  co.in_graph = true;  // ros2 node info lists the bridge's clients
  auto client = node::ServiceClient::create(participant, service, type, co);
  if (!client) return with_context(service + ": ", client.error());
  return std::unique_ptr<ForwardedService>(
      new ForwardedService(std::move(client.value()), std::move(service), options));
}

Result<Bytes> ForwardedService::call(std::span<const std::byte> request) {
  const std::lock_guard lock(mutex_);
  // A node that is not there (yet, or any more) gets no request: it would only time out.
  if (!client_.server_ready()) {
    if (Status st = client_.wait_for_server(options_.match_timeout_s); !st)
      return Error{service_ + ": the node does not serve it (no server matched within " +
                   seconds(options_.match_timeout_s) + ")"};
  }
  Result<Bytes> reply = client_.call(request, options_.call_timeout_s);
  if (!reply) return with_context(service_ + ": ", reply.error());
  return reply;
}

}  // namespace rbsim::bridge
