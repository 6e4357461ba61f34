// The in-memory backend's services (rbsim/memory_middleware.hpp): a request goes to every server of
// the service's name and type, its reply to the calling client alone.
#include <algorithm>
#include <chrono>
#include <deque>

#include "memory_state.hpp"
#include "rbsim/cdr.hpp"

namespace rbsim::node::memory {

namespace {
// A request's size counts the 16-byte request header the DDS backend puts before the body, so
// max_request_bytes drops the same requests on both.
constexpr std::size_t kHeaderBytes = 16;

std::chrono::duration<double> seconds(double s) {
  return std::chrono::duration<double>(std::max(0.0, s));
}
}  // namespace

class MemClient final : public ServiceClientImpl {
 public:
  MemClient(Network network, std::uint64_t node, std::string_view service, std::string_view srv_type,
            bool in_graph);
  ~MemClient() override;
  bool server_ready() const override;
  Status wait_for_server(double timeout_s) override;
  Result<std::int64_t> send(std::span<const std::byte> request) override;
  bool take_reply(RequestHeader& header, Bytes& reply) override;
  bool wait_reply(double timeout_s) override;
  std::uint64_t id() const override { return id_; }

  // Under the network's mutex.
  void deliver(const RequestHeader& header, std::span<const std::byte> body) {
    replies_.push_back({header, Bytes(body.begin(), body.end())});
    replied_.notify_all();
  }
  bool ready_locked() const;

 private:
  struct Reply {
    RequestHeader header;
    Bytes body;
  };
  Network network_;
  std::string service_, type_;
  std::uint64_t id_ = 0;
  std::int64_t next_seq_ = 0;
  std::deque<Reply> replies_;
  std::condition_variable replied_;
};

class MemServer final : public ServiceServerImpl {
 public:
  MemServer(Network network, std::uint64_t node, std::string_view service, std::string_view srv_type,
            const ServiceOptions& options);
  ~MemServer() override;
  std::size_t serve(const ServiceHandler& handler, std::size_t budget) override;
  // Delivers a reply to the calling client alone (serve()'s, or a deferred one).
  void reply(const RequestHeader& header, std::span<const std::byte> body) override;
  bool wait(double timeout_s) override;
  ServiceStats stats() const override;

  // Under the network's mutex: queues a request as the DDS server's listener does.
  void queue(const RequestHeader& header, std::span<const std::byte> body);
  const std::string& service() const { return service_; }
  const std::string& type() const { return type_; }

 private:
  struct Request {
    RequestHeader header;
    Bytes body;
  };
  Network network_;
  std::string service_, type_;
  ServiceOptions options_;
  std::uint64_t id_ = 0;
  std::deque<Request> queue_;
  std::condition_variable arrived_;
  ServiceStats stats_;
  Request current_;
  Bytes reply_;
};

// ---------------------------------------------------------------------------------------------
MemServer::MemServer(Network network, std::uint64_t node, std::string_view service, std::string_view srv_type,
                     const ServiceOptions& options)
    : network_(std::move(network)), service_(service), type_(srv_type), options_(options) {
  options_.queue_limit = std::max<std::size_t>(options.queue_limit, 1);
  MemoryNetwork::State& s = network_->state();
  const std::lock_guard lock(s.mutex);
  id_ =
      s.add_endpoint(node, options.in_graph, {MemoryNetwork::Endpoint::Kind::ServiceServer, service_, type_});
  s.servers.push_back(this);
  s.matched.notify_all();
}

MemServer::~MemServer() {
  MemoryNetwork::State& s = network_->state();
  const std::lock_guard lock(s.mutex);
  std::erase(s.servers, this);
  s.remove_endpoint(id_);
  s.matched.notify_all();
}

void MemServer::queue(const RequestHeader& header, std::span<const std::byte> body) {
  ++stats_.received;
  if (body.size() + kHeaderBytes > options_.max_request_bytes) {
    ++stats_.dropped_large;
    return;
  }
  if (queue_.size() >= options_.queue_limit) {
    ++stats_.dropped_full;
    return;
  }
  if (!msgs::CdrCursor::plain_header(body)) {
    ++stats_.malformed;
    return;
  }
  queue_.push_back({header, Bytes(body.begin(), body.end())});
  arrived_.notify_all();
  // Under the network's mutex, as DDS calls it on its listener thread: the server cannot go
  // meanwhile.
  if (options_.on_arrival) options_.on_arrival();
}

void MemServer::reply(const RequestHeader& header, std::span<const std::byte> body) {
  MemoryNetwork::State& s = network_->state();
  const std::lock_guard lock(s.mutex);
  if (body.size() < msgs::CdrCursor::kHeader) {  // the handler wrote no CDR message
    ++stats_.write_failed;
    return;
  }
  const auto client = std::find_if(s.clients.begin(), s.clients.end(),
                                   [&](const MemClient* c) { return c->id() == header.guid; });
  if (client == s.clients.end()) {
    ++stats_.client_gone;
    return;
  }
  (*client)->deliver(header, body);
  ++stats_.answered;
}

std::size_t MemServer::serve(const ServiceHandler& handler, std::size_t budget) {
  std::size_t handled = 0;
  while (handled < budget) {
    {
      const std::lock_guard lock(network_->state().mutex);
      if (queue_.empty()) break;
      current_ = std::move(queue_.front());
      queue_.pop_front();
    }
    ++handled;
    reply_.clear();
    if (!handler(current_.header, current_.body, reply_)) {
      const std::lock_guard lock(network_->state().mutex);
      ++stats_.unanswered;
      continue;
    }
    reply(current_.header, reply_);
  }
  return handled;
}

bool MemServer::wait(double timeout_s) {
  std::unique_lock lock(network_->state().mutex);
  return arrived_.wait_for(lock, seconds(timeout_s), [&] { return !queue_.empty(); });
}

ServiceStats MemServer::stats() const {
  const std::lock_guard lock(network_->state().mutex);
  ServiceStats s = stats_;
  s.queued = queue_.size();
  return s;
}

// ---------------------------------------------------------------------------------------------
MemClient::MemClient(Network network, std::uint64_t node, std::string_view service, std::string_view srv_type,
                     bool in_graph)
    : network_(std::move(network)), service_(service), type_(srv_type) {
  MemoryNetwork::State& s = network_->state();
  const std::lock_guard lock(s.mutex);
  id_ = s.add_endpoint(node, in_graph, {MemoryNetwork::Endpoint::Kind::ServiceClient, service_, type_});
  s.clients.push_back(this);
}

MemClient::~MemClient() {
  MemoryNetwork::State& s = network_->state();
  const std::lock_guard lock(s.mutex);
  std::erase(s.clients, this);
  s.remove_endpoint(id_);
}

bool MemClient::ready_locked() const {
  const auto& servers = network_->state().servers;
  return std::any_of(servers.begin(), servers.end(),
                     [&](const MemServer* s) { return s->service() == service_ && s->type() == type_; });
}

bool MemClient::server_ready() const {
  const std::lock_guard lock(network_->state().mutex);
  return ready_locked();
}

Status MemClient::wait_for_server(double timeout_s) {
  MemoryNetwork::State& s = network_->state();
  std::unique_lock lock(s.mutex);
  if (!s.matched.wait_for(lock, seconds(timeout_s), [&] { return ready_locked(); }))
    return Error{"no service server matched in time"};
  return Ok{};
}

Result<std::int64_t> MemClient::send(std::span<const std::byte> request) {
  if (request.size() < msgs::CdrCursor::kHeader)
    return Error{"a request must be a CDR message", ErrorCode::InvalidArgument};
  MemoryNetwork::State& s = network_->state();
  const std::lock_guard lock(s.mutex);
  const RequestHeader header{id_, ++next_seq_};
  for (MemServer* server : s.servers) {
    if (server->service() == service_ && server->type() == type_) server->queue(header, request);
  }
  return header.seq;
}

bool MemClient::take_reply(RequestHeader& header, Bytes& reply) {
  const std::lock_guard lock(network_->state().mutex);
  if (replies_.empty()) return false;
  header = replies_.front().header;
  std::swap(reply, replies_.front().body);
  replies_.pop_front();
  return true;
}

bool MemClient::wait_reply(double timeout_s) {
  std::unique_lock lock(network_->state().mutex);
  return replied_.wait_for(lock, seconds(timeout_s), [&] { return !replies_.empty(); });
}

// ---------------------------------------------------------------------------------------------
Result<std::unique_ptr<ServiceServerImpl>> make_server(const Network& network, std::uint64_t node,
                                                       std::string_view service, std::string_view srv_type,
                                                       const ServiceOptions& options) {
  return std::unique_ptr<ServiceServerImpl>(new MemServer(network, node, service, srv_type, options));
}

Result<std::unique_ptr<ServiceClientImpl>> make_client(const Network& network, std::uint64_t node,
                                                       std::string_view service, std::string_view srv_type,
                                                       const ClientOptions& options) {
  return std::unique_ptr<ServiceClientImpl>(
      new MemClient(network, node, service, srv_type, options.in_graph));
}

}  // namespace rbsim::node::memory
