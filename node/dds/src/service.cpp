// ROS 2 services on Cyclone DDS, rmw_cyclonedds_cpp's way (rbsim/dds.hpp): the raw-CDR sertype
// under the service's request and response type names, the request header spliced before the body.
#include "rbsim/service.hpp"

#include <dds/dds.h>
#include <dds/ddsi/ddsi_serdata.h>
#include <dds/ddsi/ddsi_sertype.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <optional>
#include <thread>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <vector>

#include "dds_backend.hpp"
#include "raw_serdata.hpp"
#include "rbsim/assert.hpp"
#include "rbsim/cdr.hpp"
#include "rbsim/time.hpp"
#include "rbsim/type_hash.hpp"

namespace rbsim::node {

using Clock = std::chrono::steady_clock;

namespace {

dds_duration_t to_dds(double seconds) {
  return static_cast<dds_duration_t>(seconds_to_ns_clamped(seconds));
}

// rmw_qos_profile_services_default as rmw_cyclonedds_cpp turns it into DDS QoS: reliable, volatile,
// keep last 10, no autodispose, and the endpoint's USER_DATA. rmw_cyclonedds lets a reliable writer
// block for ever; ours block at most `max_blocking` (keep-last writers seldom block at all), so a
// stuck peer never stalls the node. Reliability's blocking time is not part of QoS matching.
dds_qos_t* service_qos(const std::string& user_data, std::int32_t depth, dds_duration_t max_blocking) {
  dds_qos_t* qos = dds_create_qos();
  dds_qset_writer_data_lifecycle(qos, false);
  dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, depth);
  dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, max_blocking);
  dds_qset_durability(qos, DDS_DURABILITY_VOLATILE);
  dds_qset_liveliness(qos, DDS_LIVELINESS_AUTOMATIC, DDS_INFINITY);
  dds_qset_userdata(qos, user_data.data(), user_data.size());
  return qos;
}

// The id rmw_cyclonedds_cpp gives a client or a service (get_unique_csid, csid_to_string): the
// participant's GUID prefix and a per-process counter, big endian, printed as hex bytes joined by
// '.', the first one padded to two characters. Only equality matters: a server compares the id of a
// client's request writer with those of the reply readers it matched.
std::string endpoint_pair_id(dds_entity_t participant) {
  static std::atomic<std::uint32_t> counter{0};
  const std::uint32_t x = ++counter;
  dds_guid_t guid{};
  (void)dds_get_guid(participant, &guid);
  std::array<std::uint8_t, 16> id{};
  std::memcpy(id.data(), guid.v, 12);
  for (int i = 0; i < 4; ++i) id[12 + i] = static_cast<std::uint8_t>(x >> (24 - 8 * i));
  char buf[4];
  std::snprintf(buf, sizeof buf, "%2x", id[0]);
  std::string s = buf;
  for (std::size_t i = 1; i < id.size(); ++i) {
    std::snprintf(buf, sizeof buf, ".%x", id[i]);
    s += buf;
  }
  return s;
}

// The value of `key` in USER_DATA of the form "k1=v1;k2=v2;" (rmw's key-value encoding).
std::optional<std::string> user_data_value(const dds_qos_t* qos, std::string_view key) {
  void* data = nullptr;
  std::size_t size = 0;
  if (qos == nullptr || !dds_qget_userdata(qos, &data, &size) || data == nullptr) return std::nullopt;
  const std::string text(static_cast<const char*>(data), size);
  dds_free(data);
  std::size_t at = 0;
  while (at < text.size()) {
    const std::size_t end = std::min(text.find(';', at), text.size());
    const std::string_view item(text.data() + at, end - at);
    const std::size_t eq = item.find('=');
    if (eq != std::string_view::npos && item.substr(0, eq) == key) return std::string(item.substr(eq + 1));
    at = end + 1;
  }
  return std::nullopt;
}

EndpointId endpoint_id(dds_entity_t entity) {
  EndpointId id;
  dds_guid_t guid{};
  if (dds_get_guid(entity, &guid) >= 0) std::memcpy(id.guid.data(), guid.v, id.guid.size());
  dds_instance_handle_t ih = 0;
  if (dds_get_instance_handle(entity, &ih) >= 0) id.instance_handle = ih;
  return id;
}

// Copies a taken sample's bytes into `out` (replaced).
void sample_bytes(ddsi_serdata* d, Bytes& out) {
  const std::uint32_t size = ddsi_serdata_size(d);
  out.resize(size);
  if (size > 0) ddsi_serdata_to_ser(d, 0, size, out.data());
}

}  // namespace

// The types the servers' and clients' Impl hold live in a named namespace: a class with members of
// anonymous-namespace types breaks -Wsubobject-linkage in a unity build (scripts/test's Release
// stage), where this file is included into another.
namespace service_detail {

// A request and a reply topic with their endpoints, deleted together.
struct Endpoints {
  dds_entity_t writer_topic = 0, reader_topic = 0, writer = 0, reader = 0;
  const ddsi_sertype* writer_type = nullptr;
  void remove() {
    // The reader first: deleting it waits for a listener call in progress.
    for (dds_entity_t* e : {&reader, &writer, &reader_topic, &writer_topic}) {
      if (*e > 0) dds_delete(*e);
      *e = 0;
    }
  }
};

// Creates both topics and endpoints; `listener` (may be null) goes to the reader.
Status make_endpoints(dds_entity_t participant, const std::string& writer_topic,
                      const std::string& writer_type, const std::string& writer_user_data,
                      const std::string& reader_topic, const std::string& reader_type,
                      const std::string& reader_user_data, std::int32_t reader_depth,
                      dds_duration_t writer_blocking, const dds_listener_t* listener, Endpoints& out) {
  auto wt = make_raw_topic(participant, writer_topic, writer_type, &out.writer_type);
  if (!wt) return wt.error();
  out.writer_topic = wt.value();
  auto rt = make_raw_topic(participant, reader_topic, reader_type, nullptr);
  if (!rt) return rt.error();
  out.reader_topic = rt.value();
  dds_qos_t* wq = service_qos(writer_user_data, 10, writer_blocking);
  out.writer = dds_create_writer(participant, out.writer_topic, wq, nullptr);
  dds_delete_qos(wq);
  if (out.writer < 0) return dds_error("cannot create DDS writer on " + writer_topic, out.writer);
  dds_qos_t* rq = service_qos(reader_user_data, reader_depth, DDS_INFINITY);
  out.reader = dds_create_reader(participant, out.reader_topic, rq, listener);
  dds_delete_qos(rq);
  if (out.reader < 0) return dds_error("cannot create DDS reader on " + reader_topic, out.reader);
  return Ok{};
}

// Matched counts of an endpoint: a cache built from the matched endpoints stays valid while they
// are unchanged (any match or unmatch changes the total or the current count).
struct MatchState {
  std::uint32_t total = UINT32_MAX;
  std::uint32_t current = UINT32_MAX;
  bool operator==(const MatchState&) const = default;
};
MatchState publication_state(dds_entity_t writer) {
  dds_publication_matched_status_t st{};
  if (dds_get_publication_matched_status(writer, &st) < 0) return {0, 0};
  return {st.total_count, st.current_count};
}
MatchState subscription_state(dds_entity_t reader) {
  dds_subscription_matched_status_t st{};
  if (dds_get_subscription_matched_status(reader, &st) < 0) return {0, 0};
  return {st.total_count, st.current_count};
}

}  // namespace service_detail
using service_detail::Endpoints;
using service_detail::make_endpoints;
using service_detail::MatchState;
using service_detail::publication_state;
using service_detail::subscription_state;

// ---------------------------------------------------------------------------------------------
// Names and the sample layout

std::string service_request_topic(std::string_view service) {
  return "rq" + std::string(service.starts_with('/') ? "" : "/") + std::string(service) + "Request";
}
std::string service_reply_topic(std::string_view service) {
  return "rr" + std::string(service.starts_with('/') ? "" : "/") + std::string(service) + "Reply";
}
std::string service_request_type(std::string_view srv_type) {
  return msgs::dds_type_name(std::string(srv_type) + "_Request");
}
std::string service_response_type(std::string_view srv_type) {
  return msgs::dds_type_name(std::string(srv_type) + "_Response");
}

void wrap_service_sample(const RequestHeader& header, std::span<const std::byte> body, Bytes& out) {
  RBSIM_ASSERT(body.size() >= msgs::CdrCursor::kHeader, "a service body is a CDR message");
  // The encapsulation header stays the body's: its padding count (options) still holds, as the
  // total grows by 16 bytes.
  out.resize(body.size() + kRequestHeaderBytes);
  std::memcpy(out.data(), body.data(), msgs::CdrCursor::kHeader);
  std::memcpy(out.data() + 4, &header.guid, 8);
  std::memcpy(out.data() + 12, &header.seq, 8);
  std::memcpy(out.data() + 4 + kRequestHeaderBytes, body.data() + 4, body.size() - 4);
}

Result<RequestHeader> unwrap_service_sample(std::span<const std::byte> sample, Bytes& body) {
  if (!msgs::CdrCursor::plain_header(sample)) {
    return Error{"not a plain little-endian CDR sample (encapsulation header 00 01)", ErrorCode::Malformed};
  }
  msgs::CdrCursor at(sample);
  RequestHeader h;
  if (!at.read(h.guid) || !at.read(h.seq)) {
    return Error{
        "a service sample of " + std::to_string(sample.size()) + " bytes has no room for the request header",
        ErrorCode::Truncated};
  }
  body.resize(sample.size() - kRequestHeaderBytes);
  std::memcpy(body.data(), sample.data(), msgs::CdrCursor::kHeader);
  std::memcpy(body.data() + 4, sample.data() + 4 + kRequestHeaderBytes, body.size() - 4);
  return h;
}

// ---------------------------------------------------------------------------------------------
// Server

struct DdsServer final : ServiceServerImpl {
  std::string service;
  ServiceOptions options;
  dds_entity_t participant = 0;
  Endpoints dds;               // writer: replies, reader: requests
  std::weak_ptr<Graph> graph;  // where its endpoints are listed

  // Filled by the listener on Cyclone's receive thread, emptied by serve(): a ring of slots whose
  // buffers are reused, so a steady stream of requests does not allocate.
  struct Slot {
    RequestHeader header;
    std::uint64_t publication = 0;  // the request writer's instance handle (the client)
    Bytes body;
  };
  mutable std::mutex mu;
  std::condition_variable arrived;
  std::vector<Slot> ring;
  std::size_t head = 0, count = 0;
  ServiceStats stats_;  // stats_.pending: pending.size() as serve() left it

  // The caller's thread only (serve()).
  struct Pending {
    RequestHeader header;
    std::uint64_t publication = 0;
    Bytes reply;
    Clock::time_point deadline;
  };
  std::vector<Pending> pending;
  Slot current;
  Bytes answer, sample, taken;
  // The clientid of each matched request writer (none: it sent none), and the clientids of the
  // matched reply readers, each valid while the match counts they were read at hold.
  std::unordered_map<std::uint64_t, std::optional<std::string>> writer_ids;
  std::unordered_set<std::string> reader_ids;
  MatchState writers_at, readers_at;

  ~DdsServer() override {
    if (dds.reader > 0) unlist_endpoint(graph, dds.reader);
    if (dds.writer > 0) unlist_endpoint(graph, dds.writer);
    dds.remove();
  }

  std::size_t serve(const ServiceHandler& handler, std::size_t budget) override;
  void reply(const RequestHeader& header, std::span<const std::byte> body) override {
    deliver(header, header.route, body);
  }
  bool wait(double timeout_s) override;
  ServiceStats stats() const override;

  static void on_data(dds_entity_t reader, void* arg) { static_cast<DdsServer*>(arg)->take_all(reader); }

  void take_all(dds_entity_t reader) {
    while (true) {
      ddsi_serdata* d = nullptr;
      dds_sample_info_t info{};
      if (dds_takecdr(reader, &d, 1, &info, DDS_ANY_STATE) <= 0) return;
      if (info.valid_data) queue(d, info.publication_handle);
      ddsi_serdata_unref(d);
    }
  }

  void queue(ddsi_serdata* d, std::uint64_t publication) {
    std::lock_guard lock(mu);
    ++stats_.received;
    if (ddsi_serdata_size(d) > options.max_request_bytes) {
      ++stats_.dropped_large;  // never copied
      return;
    }
    if (count == ring.size()) {
      ++stats_.dropped_full;
      return;
    }
    sample_bytes(d, taken);
    Slot& slot = ring[(head + count) % ring.size()];
    auto header = unwrap_service_sample(taken, slot.body);
    if (!header) {
      ++stats_.malformed;
      return;
    }
    slot.header = header.value();
    slot.publication = publication;
    ++count;
    arrived.notify_one();
    if (options.on_arrival) options.on_arrival();
  }

  enum class Client : std::uint8_t { Present, NotYet, Gone };
  // Whether the client that sent a request (its request writer's handle) can get the reply, as
  // rmw_cyclonedds's check_for_response_reader decides: gone when its request writer is no longer
  // matched; present when it carries no clientid (older clients) or one of our reply writer's
  // matched readers carries the same clientid; else not yet.
  Client client(std::uint64_t publication) {
    const MatchState w = subscription_state(dds.reader);
    if (!(w == writers_at)) {
      writer_ids.clear();
      writers_at = w;
    }
    auto it = writer_ids.find(publication);
    if (it == writer_ids.end()) {
      dds_builtintopic_endpoint_t* e = dds_get_matched_publication_data(dds.reader, publication);
      if (e == nullptr) return Client::Gone;
      it = writer_ids.emplace(publication, user_data_value(e->qos, "clientid")).first;
      dds_builtintopic_free_endpoint(e);
    }
    if (!it->second) return Client::Present;
    const MatchState r = publication_state(dds.writer);
    if (!(r == readers_at)) refresh_reader_ids(r);
    return reader_ids.contains(*it->second) ? Client::Present : Client::NotYet;
  }

  void refresh_reader_ids(MatchState at) {
    reader_ids.clear();
    readers_at = at;
    std::vector<dds_instance_handle_t> handles(std::size_t{at.current == UINT32_MAX ? 0 : at.current} + 8);
    const dds_return_t n = dds_get_matched_subscriptions(dds.writer, handles.data(), handles.size());
    for (dds_return_t i = 0; i < std::min<dds_return_t>(n, static_cast<dds_return_t>(handles.size())); ++i) {
      dds_builtintopic_endpoint_t* e = dds_get_matched_subscription_data(dds.writer, handles[i]);
      if (e == nullptr) continue;
      if (auto id = user_data_value(e->qos, "clientid")) reader_ids.insert(*id);
      dds_builtintopic_free_endpoint(e);
    }
    // More readers than room: the next call reads them again (the cache stays invalid).
    if (n > static_cast<dds_return_t>(handles.size())) readers_at = {};
  }

  void count_one(std::uint64_t ServiceStats::*field) {
    std::lock_guard lock(mu);
    ++(stats_.*field);
  }

  void write(const RequestHeader& header, std::span<const std::byte> body) {
    if (body.size() < msgs::CdrCursor::kHeader) {  // the handler wrote no CDR message
      count_one(&ServiceStats::write_failed);
      return;
    }
    wrap_service_sample(header, body, sample);
    ddsi_serdata* d = make_raw_serdata(dds.writer_type, sample);
    const dds_return_t rc = dds_writecdr(dds.writer, d);  // takes the reference
    count_one(rc < 0 ? &ServiceStats::write_failed : &ServiceStats::answered);
  }

  void deliver(const RequestHeader& header, std::uint64_t publication, std::span<const std::byte> body) {
    switch (client(publication)) {
      case Client::Present:
        write(header, body);
        return;
      case Client::Gone:
        count_one(&ServiceStats::client_gone);
        return;
      case Client::NotYet:
        if (pending.size() >= options.queue_limit) {
          count_one(&ServiceStats::client_unmatched);
          return;
        }
        pending.push_back(
            {header, publication, Bytes(body.begin(), body.end()),
             Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                std::chrono::duration<double>(options.client_match_timeout_s))});
        return;
    }
  }

  void retry_pending() {
    const auto now = Clock::now();
    std::erase_if(pending, [&](const Pending& p) {
      switch (client(p.publication)) {
        case Client::Present:
          write(p.header, p.reply);
          return true;
        case Client::Gone:
          count_one(&ServiceStats::client_gone);
          return true;
        case Client::NotYet:
          break;
      }
      if (now < p.deadline) return false;
      count_one(&ServiceStats::client_unmatched);
      return true;
    });
  }

  bool pop() {
    std::lock_guard lock(mu);
    if (count == 0) return false;
    Slot& slot = ring[head];
    current.header = slot.header;
    current.publication = slot.publication;
    std::swap(current.body, slot.body);  // both buffers keep their storage
    head = (head + 1) % ring.size();
    --count;
    return true;
  }
};

namespace {
// The USER_DATA "typehash=RIHS01_...;" of a node's service endpoints (a server's or a client's), as
// rmw_cyclonedds_cpp writes it; empty under Humble, which has no type hashes.
Status type_hash_user_data(const DdsContext& context, std::string_view srv_type, bool in_graph,
                           std::string& request, std::string& reply) {
  if (!in_graph || !has_type_hashes(context.distro)) return Ok{};
  Result<msgs::ServiceEndpointHashes> h = msgs::service_endpoint_type_hashes(srv_type);
  if (!h) return h.error();
  request = msgs::typehash_user_data(h->request);
  reply = msgs::typehash_user_data(h->reply);
  return Ok{};
}
}  // namespace

Result<std::unique_ptr<ServiceServerImpl>> make_dds_server(const DdsContext& context,
                                                           std::string_view service,
                                                           std::string_view srv_type,
                                                           const ServiceOptions& options,
                                                           const DdsServiceUserData& extra) {
  std::string request_hash, reply_hash;
  if (Status st = type_hash_user_data(context, srv_type, options.in_graph, request_hash, reply_hash); !st)
    return st.error();
  auto impl = std::make_unique<DdsServer>();
  impl->service = std::string(service);
  impl->options = options;
  impl->options.queue_limit = std::max<std::size_t>(options.queue_limit, 1);
  impl->ring.resize(impl->options.queue_limit);
  impl->participant = context.participant;
  const std::string user_data = "serviceid=" + endpoint_pair_id(context.participant) + ";";
  dds_listener_t* listener = dds_create_listener(impl.get());
  dds_lset_data_available(listener, &DdsServer::on_data);
  // The reader keeps as many requests as the queue: the listener drains it as they arrive, so the
  // queue, where drops are counted, is where a flood is cut.
  const auto depth = static_cast<std::int32_t>(std::min<std::size_t>(impl->options.queue_limit, INT32_MAX));
  Status st = make_endpoints(
      context.participant, service_reply_topic(service), service_response_type(srv_type),
      user_data + reply_hash + extra.reply, service_request_topic(service), service_request_type(srv_type),
      user_data + request_hash + extra.request, std::max(depth, 10), DDS_MSECS(10), listener, impl->dds);
  dds_delete_listener(listener);
  if (!st) return with_context("service " + std::string(service) + ": ", st.error());
  if (options.in_graph && context.graph) {  // ros2 node info lists the node's services
    if (Status g = context.graph->add(Graph::Kind::Reader, Graph::guid_of(impl->dds.reader)); !g)
      return g.error();
    if (Status g = context.graph->add(Graph::Kind::Writer, Graph::guid_of(impl->dds.writer)); !g)
      return g.error();
    impl->graph = context.graph;
  }
  return std::unique_ptr<ServiceServerImpl>(std::move(impl));
}

std::size_t DdsServer::serve(const ServiceHandler& handler, std::size_t budget) {
  if (!pending.empty()) retry_pending();
  std::size_t handled = 0;
  while (handled < budget && pop()) {
    ++handled;
    current.header.route = current.publication;
    answer.clear();
    if (!handler(current.header, current.body, answer)) {
      count_one(&ServiceStats::unanswered);
      continue;
    }
    deliver(current.header, current.publication, answer);
  }
  std::lock_guard lock(mu);
  stats_.pending = pending.size();  // for stats() from any thread
  return handled;
}

bool DdsServer::wait(double timeout_s) {
  std::unique_lock lock(mu);
  return arrived.wait_for(lock, std::chrono::duration<double>(std::max(0.0, timeout_s)),
                          [&] { return count > 0; });
}

ServiceStats DdsServer::stats() const {
  std::lock_guard lock(mu);
  ServiceStats s = stats_;
  s.queued = count;
  return s;
}

// ---------------------------------------------------------------------------------------------
// Client

struct DdsClient final : ServiceClientImpl {
  Endpoints dds;  // writer: requests, reader: replies
  dds_entity_t waitset = 0, condition = 0;
  std::uint64_t client_id = 0;
  std::int64_t next_seq = 0;
  Bytes sample, taken;
  std::weak_ptr<Graph> graph;  // where its endpoints are listed
  ~DdsClient() override {
    if (dds.writer > 0) unlist_endpoint(graph, dds.writer);
    if (dds.reader > 0) unlist_endpoint(graph, dds.reader);
    if (waitset > 0) dds_delete(waitset);
    dds.remove();  // the read condition goes with its reader
  }
  bool server_ready() const override;
  Status wait_for_server(double timeout_s) override;
  Result<std::int64_t> send(std::span<const std::byte> request) override;
  bool take_reply(RequestHeader& header, Bytes& reply) override;
  bool wait_reply(double timeout_s) override;
  std::uint64_t id() const override { return client_id; }
};

Result<std::unique_ptr<ServiceClientImpl>> make_dds_client(const DdsContext& context,
                                                           std::string_view service,
                                                           std::string_view srv_type,
                                                           const ClientOptions& options,
                                                           const DdsServiceUserData& extra) {
  std::string request_hash, reply_hash;
  if (Status st = type_hash_user_data(context, srv_type, options.in_graph, request_hash, reply_hash); !st)
    return st.error();
  auto impl = std::make_unique<DdsClient>();
  const std::string user_data = "clientid=" + endpoint_pair_id(context.participant) + ";";
  Status st = make_endpoints(context.participant, service_request_topic(service),
                             service_request_type(srv_type), user_data + request_hash + extra.request,
                             service_reply_topic(service), service_response_type(srv_type),
                             user_data + reply_hash + extra.reply, 10, DDS_SECS(1), nullptr, impl->dds);
  if (!st) return with_context("client of " + std::string(service) + ": ", st.error());
  impl->client_id = endpoint_id(impl->dds.writer).instance_handle;
  impl->condition = dds_create_readcondition(impl->dds.reader, DDS_ANY_STATE);
  impl->waitset = dds_create_waitset(context.participant);
  if (impl->condition < 0 || impl->waitset < 0 || dds_waitset_attach(impl->waitset, impl->condition, 0) < 0) {
    return Error{"client of " + std::string(service) + ": cannot create its DDS wait set"};
  }
  if (options.in_graph && context.graph) {  // ros2 node info lists the node's clients
    if (Status g = context.graph->add(Graph::Kind::Writer, Graph::guid_of(impl->dds.writer)); !g)
      return g.error();
    if (Status g = context.graph->add(Graph::Kind::Reader, Graph::guid_of(impl->dds.reader)); !g)
      return g.error();
    impl->graph = context.graph;
  }
  return std::unique_ptr<ServiceClientImpl>(std::move(impl));
}

bool DdsClient::server_ready() const {
  return publication_state(dds.writer).current > 0 && subscription_state(dds.reader).current > 0;
}

Status DdsClient::wait_for_server(double timeout_s) {
  const auto end =
      Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(timeout_s));
  while (!server_ready()) {
    if (Clock::now() >= end) return Error{"no service server matched in time"};
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return Ok{};
}

Result<std::int64_t> DdsClient::send(std::span<const std::byte> request) {
  if (request.size() < msgs::CdrCursor::kHeader)
    return Error{"a request must be a CDR message", ErrorCode::InvalidArgument};
  const RequestHeader header{client_id, ++next_seq};
  wrap_service_sample(header, request, sample);
  ddsi_serdata* d = make_raw_serdata(dds.writer_type, sample);
  const dds_return_t rc = dds_writecdr(dds.writer, d);
  if (rc < 0) return dds_error("sending a request failed", rc);
  return header.seq;
}

bool DdsClient::take_reply(RequestHeader& header, Bytes& reply) {
  while (true) {
    ddsi_serdata* d = nullptr;
    dds_sample_info_t info{};
    if (dds_takecdr(dds.reader, &d, 1, &info, DDS_ANY_STATE) <= 0) return false;
    if (info.valid_data) sample_bytes(d, taken);
    ddsi_serdata_unref(d);
    if (!info.valid_data) continue;
    auto h = unwrap_service_sample(taken, reply);
    if (!h || h.value().guid != client_id) continue;  // malformed, or another client's
    header = h.value();
    return true;
  }
}

bool DdsClient::wait_reply(double timeout_s) {
  return dds_waitset_wait(waitset, nullptr, 0, to_dds(timeout_s)) > 0;
}

// ---------------------------------------------------------------------------------------------
// The DDS side of the service handles

Result<ServiceServer> create_dds_server(const Participant& participant, std::string_view service,
                                        std::string_view srv_type, const ServiceOptions& options,
                                        const DdsServiceUserData& user_data) {
  const auto* p = dynamic_cast<const DdsParticipant*>(&participant.impl());
  if (p == nullptr) return Error{"create_dds_server: not a DDS participant", ErrorCode::InvalidArgument};
  auto impl = make_dds_server(p->context(), service, srv_type, options, user_data);
  if (!impl) return impl.error();
  return ServiceServer(std::move(impl.value()), std::string(service));
}

Result<ServiceClient> create_dds_client(const Participant& participant, std::string_view service,
                                        std::string_view srv_type, const ClientOptions& options,
                                        const DdsServiceUserData& user_data) {
  const auto* p = dynamic_cast<const DdsParticipant*>(&participant.impl());
  if (p == nullptr) return Error{"create_dds_client: not a DDS participant", ErrorCode::InvalidArgument};
  auto impl = make_dds_client(p->context(), service, srv_type, options, user_data);
  if (!impl) return impl.error();
  return ServiceClient(std::move(impl.value()));
}

EndpointId dds_request_reader(const ServiceServer& server) {
  const auto* s = dynamic_cast<const DdsServer*>(&server.impl());
  return s != nullptr ? endpoint_id(s->dds.reader) : EndpointId{};
}
EndpointId dds_reply_writer(const ServiceServer& server) {
  const auto* s = dynamic_cast<const DdsServer*>(&server.impl());
  return s != nullptr ? endpoint_id(s->dds.writer) : EndpointId{};
}
EndpointId dds_request_writer(const ServiceClient& client) {
  const auto* c = dynamic_cast<const DdsClient*>(&client.impl());
  return c != nullptr ? endpoint_id(c->dds.writer) : EndpointId{};
}
EndpointId dds_reply_reader(const ServiceClient& client) {
  const auto* c = dynamic_cast<const DdsClient*>(&client.impl());
  return c != nullptr ? endpoint_id(c->dds.reader) : EndpointId{};
}

}  // namespace rbsim::node
