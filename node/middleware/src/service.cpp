// The service handles (rbsim/service.hpp): each forwards to its backend's implementation.
#include "rbsim/service.hpp"

#include <chrono>

#include "rbsim/middleware_backend.hpp"

namespace rbsim::node {

Result<ServiceServer> ServiceServer::create(const Participant& participant, std::string_view service,
                                            std::string_view srv_type, const ServiceOptions& options) {
  auto impl = participant.impl().create_server(service, srv_type, options);
  if (!impl) return impl.error();
  ServiceServer server(std::move(impl.value()), std::string(service));
  if (options.in_graph) server.type_ = NodeTypeCache::register_type(participant.types(), srv_type);
  return server;
}

ServiceServer::ServiceServer(std::unique_ptr<ServiceServerImpl> impl, std::string service)
    : impl_(std::move(impl)), service_(std::move(service)) {}
ServiceServer::ServiceServer(ServiceServer&&) noexcept = default;
ServiceServer::~ServiceServer() = default;

std::size_t ServiceServer::serve(const Handler& handler, std::size_t budget) {
  return impl_->serve(handler, budget);
}
void ServiceServer::reply(const RequestHeader& header, std::span<const std::byte> reply) {
  impl_->reply(header, reply);
}
bool ServiceServer::wait(double timeout_s) {
  return impl_->wait(timeout_s);
}
ServiceStats ServiceServer::stats() const {
  return impl_->stats();
}

// ---------------------------------------------------------------------------------------------
Result<ServiceClient> ServiceClient::create(const Participant& participant, std::string_view service,
                                            std::string_view srv_type, const ClientOptions& options) {
  auto impl = participant.impl().create_client(service, srv_type, options);
  if (!impl) return impl.error();
  ServiceClient client(std::move(impl.value()));
  if (options.in_graph) client.type_ = NodeTypeCache::register_type(participant.types(), srv_type);
  return client;
}

ServiceClient::ServiceClient(std::unique_ptr<ServiceClientImpl> impl) : impl_(std::move(impl)) {}
ServiceClient::ServiceClient(ServiceClient&&) noexcept = default;
ServiceClient::~ServiceClient() = default;

bool ServiceClient::server_ready() const {
  return impl_->server_ready();
}
Status ServiceClient::wait_for_server(double timeout_s) {
  return impl_->wait_for_server(timeout_s);
}
Result<std::int64_t> ServiceClient::send(std::span<const std::byte> request) {
  return impl_->send(request);
}
bool ServiceClient::take_reply(RequestHeader& header, Bytes& reply) {
  return impl_->take_reply(header, reply);
}
bool ServiceClient::wait_reply(double timeout_s) {
  return impl_->wait_reply(timeout_s);
}
std::uint64_t ServiceClient::id() const {
  return impl_->id();
}

Result<Bytes> ServiceClient::call(std::span<const std::byte> request, double timeout_s) {
  using Clock = std::chrono::steady_clock;
  auto seq = send(request);
  if (!seq) return seq.error();
  const auto end =
      Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(timeout_s));
  Bytes reply;
  RequestHeader header;
  while (true) {
    while (take_reply(header, reply)) {
      if (header.seq == seq.value()) return reply;
    }
    const auto left = std::chrono::duration<double>(end - Clock::now()).count();
    if (left <= 0) return Error{"no reply within " + std::to_string(timeout_s) + " s"};
    wait_reply(left);
  }
}

}  // namespace rbsim::node
