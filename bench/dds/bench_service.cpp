// Service round trip over Cyclone DDS on loopback: our ServiceClient -> a server in another process
// -> reply, beside the same bytes on plain Cyclone pub/sub (a ping writer and an echoing pong
// process), in one run. Each peer is a server process started by this program and the client that
// calls it; a new peer (the ros2-client server) is one more row of kPeers.
//
//   rbsim_bench_service [--calls N] [--warmup N] [--domain D]   # runs every peer, prints a table
//   rbsim_bench_service serve PEER DOMAIN NAMESPACE              # the server side of PEER (internal)
//
// Payload: rbsim_msgs/srv/Step, request steps = 1 (24 bytes with the request header), response
// success, message "ok", step (36 bytes). The server answers from its polling loop, as the node
// does (serve(), then wait for the next request).
#include <dds/dds.h>
#include <dds/ddsi/ddsi_serdata.h>
#include <dds/ddsi/ddsi_sertype.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "raw_serdata.hpp"
#include "rbsim/dds.hpp"
#include "rbsim/interfaces.hpp"
#include "rbsim/service.hpp"

extern char** environ;

namespace {

using namespace rbsim;
using Clock = std::chrono::steady_clock;
constexpr std::string_view kSrv = "rbsim_msgs/srv/Step";

Bytes step_request() {
  Bytes b;
  msgs::encode(msgs::StepRequest{1}, b);
  return b;
}
Bytes step_response() {
  Bytes b;
  msgs::encode(msgs::StepResponse{true, "ok", 1}, b);
  return b;
}

// ---------------------------------------------------------------------------------------------
// Plain pub/sub: raw-CDR topics ping and pong, the samples shaped as the service's (header + body).

struct RawTopic {
  dds_entity_t topic = 0;
  const ddsi_sertype* type = nullptr;
};
RawTopic raw_topic(dds_entity_t participant, const std::string& name, const std::string& type_name) {
  ddsi_sertype* st = node::make_raw_sertype(type_name.c_str());
  RawTopic t;
  t.topic = dds_create_topic_sertype(participant, name.c_str(), &st, nullptr, nullptr, nullptr);
  t.type = st;
  return t;
}
dds_qos_t* reliable_qos() {
  dds_qos_t* q = dds_create_qos();
  dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
  dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 10);
  return q;
}

struct PubSub {
  dds_entity_t writer = 0, reader = 0, waitset = 0;
  const ddsi_sertype* type = nullptr;
  Bytes taken;
  PubSub(dds_entity_t participant, const std::string& out, const std::string& in) {
    RawTopic wt = raw_topic(participant, out, service_type("_Request_"));
    RawTopic rt = raw_topic(participant, in, service_type("_Request_"));
    dds_qos_t* q = reliable_qos();
    writer = dds_create_writer(participant, wt.topic, q, nullptr);
    reader = dds_create_reader(participant, rt.topic, q, nullptr);
    dds_delete_qos(q);
    type = wt.type;
    waitset = dds_create_waitset(participant);
    dds_waitset_attach(waitset, dds_create_readcondition(reader, DDS_ANY_STATE), 0);
  }
  static std::string service_type(const char* half) {
    return "rbsim_bench::msg::dds_::Ping" + std::string(half);
  }
  bool matched() const {
    dds_publication_matched_status_t p{};
    dds_subscription_matched_status_t s{};
    dds_get_publication_matched_status(writer, &p);
    dds_get_subscription_matched_status(reader, &s);
    return p.current_count > 0 && s.current_count > 0;
  }
  void write(std::span<const std::byte> b) { dds_writecdr(writer, node::make_raw_serdata(type, b)); }
  bool take(double timeout_s) {
    const auto end =
        Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(timeout_s));
    while (true) {
      ddsi_serdata* d = nullptr;
      dds_sample_info_t info{};
      if (dds_takecdr(reader, &d, 1, &info, DDS_ANY_STATE) > 0) {
        const bool valid = info.valid_data;
        if (valid) {
          taken.resize(ddsi_serdata_size(d));
          ddsi_serdata_to_ser(d, 0, taken.size(), taken.data());
        }
        ddsi_serdata_unref(d);
        if (valid) return true;
        continue;
      }
      const auto left = end - Clock::now();
      if (left <= Clock::duration::zero()) return false;
      dds_waitset_wait(waitset, nullptr, 0,
                       std::chrono::duration_cast<std::chrono::nanoseconds>(left).count());
    }
  }
};

// ---------------------------------------------------------------------------------------------
// Peers: the server each runs, and how this process calls it once.

volatile sig_atomic_t stop = 0;

int serve_rbsim(const node::Participant& p, const std::string& ns) {
  auto server = node::ServiceServer::create(p, ns + "/step", kSrv);
  if (!server) return std::fprintf(stderr, "%s\n", server.error().message.c_str()), 1;
  const Bytes reply = step_response();
  const auto handler = [&](const node::RequestHeader&, std::span<const std::byte> req, Bytes& out) {
    msgs::StepRequest r;
    if (!msgs::decode(req, r).ok()) return false;
    out = reply;
    return true;
  };
  while (!stop) {
    server->serve(handler);
    server->wait(0.1);
  }
  return 0;
}

int serve_pubsub(const node::Participant& p, const std::string& ns) {
  PubSub echo(dds_entity(p), "rt" + ns + "/pong", "rt" + ns + "/ping");
  Bytes reply, body;
  while (!stop) {
    if (!echo.take(0.1)) continue;
    auto h = node::unwrap_service_sample(echo.taken, body);
    if (!h) continue;
    if (reply.empty()) node::wrap_service_sample(h.value(), step_response(), reply);
    std::memcpy(reply.data() + 4, echo.taken.data() + 4, node::kRequestHeaderBytes);  // the header back
    echo.write(reply);
  }
  return 0;
}

// A client of one peer: set up (waits for the server), then one round trip per call.
struct Caller {
  std::function<bool(double)> ready;
  std::function<bool()> call;
};

// The lambdas own the client's state (shared_ptr), so a Caller is the whole client.
Caller rbsim_caller(const node::Participant& p, const std::string& ns) {
  auto client = node::ServiceClient::create(p, ns + "/step", kSrv);
  if (!client) return {};
  auto c = std::make_shared<node::ServiceClient>(std::move(client.value()));
  const Bytes req = step_request();
  return {[c](double t) { return c->wait_for_server(t).ok(); }, [c, req] { return c->call(req, 1.0).ok(); }};
}

Caller pubsub_caller(const node::Participant& p, const std::string& ns) {
  auto ps = std::make_shared<PubSub>(dds_entity(p), "rt" + ns + "/ping", "rt" + ns + "/pong");
  auto sample = std::make_shared<Bytes>();
  auto seq = std::make_shared<std::int64_t>(0);
  return {[ps](double t) {
            const auto end =
                Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(t));
            while (!ps->matched()) {
              if (Clock::now() > end) return false;
              dds_sleepfor(DDS_MSECS(5));
            }
            return true;
          },
          [ps, sample, seq] {
            node::wrap_service_sample({1, ++*seq}, step_request(), *sample);
            ps->write(*sample);
            return ps->take(1.0);
          }};
}

struct Peer {
  const char* name;
  const char* what;
  int (*serve)(const node::Participant&, const std::string&);
  Caller (*caller)(const node::Participant&, const std::string&);
};
// A ros2-client (Rust) peer later: its server started from its own binary, called with our client.
const Peer kPeers[] = {
    {"rbsim", "ServiceClient -> ServiceServer (Step)", serve_rbsim, rbsim_caller},
    {"pubsub", "raw Cyclone ping -> echo (same bytes)", serve_pubsub, pubsub_caller},
};

const Peer* find_peer(std::string_view name) {
  for (const Peer& p : kPeers)
    if (name == p.name) return &p;
  return nullptr;
}

struct Row {
  const Peer* peer;
  std::vector<double> us;
  int failed = 0;
};

double quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(q * static_cast<double>(v.size())))];
}

int run_peer(const Peer& peer, std::uint32_t domain, int calls, int warmup, Row& row) {
  const std::string ns = "/bench_service_" + std::to_string(getpid()) + "_" + peer.name;
  const std::string d = std::to_string(domain);
  char* argv[] = {const_cast<char*>("rbsim_bench_service"),
                  const_cast<char*>("serve"),
                  const_cast<char*>(peer.name),
                  const_cast<char*>(d.c_str()),
                  const_cast<char*>(ns.c_str()),
                  nullptr};
  pid_t pid = 0;
  if (posix_spawn(&pid, "/proc/self/exe", nullptr, nullptr, argv, environ) != 0) return 1;
  int rc = 1;
  {
    auto participant = node::create_dds_participant(domain);
    if (participant) {
      Caller c = peer.caller(participant.value(), ns);
      if (c.ready && c.ready(10.0)) {
        dds_sleepfor(DDS_MSECS(200));  // both directions discovered
        for (int i = 0; i < warmup; ++i) (void)c.call();
        for (int i = 0; i < calls; ++i) {
          const auto t0 = Clock::now();
          const bool ok = c.call();
          const double us = std::chrono::duration<double, std::micro>(Clock::now() - t0).count();
          if (ok)
            row.us.push_back(us);
          else
            ++row.failed;
        }
        rc = 0;
      } else {
        std::fprintf(stderr, "peer %s: no server\n", peer.name);
      }
    }
  }
  kill(pid, SIGTERM);
  int status = 0;
  waitpid(pid, &status, 0);
  return rc;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc == 5 && std::string_view(argv[1]) == "serve") {
    const Peer* peer = find_peer(argv[2]);
    if (peer == nullptr) return 2;
    signal(SIGTERM, [](int) { stop = 1; });
    auto participant = node::create_dds_participant(static_cast<std::uint32_t>(std::atoi(argv[3])));
    if (!participant) return 1;
    return peer->serve(participant.value(), argv[4]);
  }
  int calls = 5000, warmup = 200;
  std::uint32_t domain = 171;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string_view a = argv[i];
    if (a == "--calls")
      calls = std::atoi(argv[i + 1]);
    else if (a == "--warmup")
      warmup = std::atoi(argv[i + 1]);
    else if (a == "--domain")
      domain = static_cast<std::uint32_t>(std::atoi(argv[i + 1]));
    else
      return std::fprintf(stderr, "usage: rbsim_bench_service [--calls N] [--warmup N] [--domain D]\n"), 2;
  }
  std::printf("service round trip, Step (24 B request, 36 B reply), %d calls after %d warm-up, loopback\n",
              calls, warmup);
  std::printf("%-8s %-42s %10s %10s %10s %7s\n", "peer", "path", "median us", "p99 us", "mean us", "failed");
  std::vector<Row> rows;
  for (const Peer& p : kPeers) {
    Row row{&p, {}, 0};
    if (run_peer(p, domain, calls, warmup, row) != 0) return 1;
    double mean = 0;
    for (double v : row.us) mean += v / static_cast<double>(row.us.size());
    std::printf("%-8s %-42s %10.1f %10.1f %10.1f %7d\n", p.name, p.what, quantile(row.us, 0.5),
                quantile(row.us, 0.99), mean, row.failed);
    rows.push_back(std::move(row));
  }
  std::printf("rbsim / pubsub: median %.2fx, p99 %.2fx\n",
              quantile(rows[0].us, 0.5) / quantile(rows[1].us, 0.5),
              quantile(rows[0].us, 0.99) / quantile(rows[1].us, 0.99));
  return 0;
}
