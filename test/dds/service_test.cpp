// ROS 2 services on Cyclone DDS (rbsim/service.hpp) over the loopback configuration, in one
// process: names and sample layout, our client against our server, two clients, a client that
// vanishes, a client whose reply reader never matches, hostile samples from a raw writer, a flood.
#include "rbsim/service.hpp"
#include "rbsim/dds.hpp"
#include "step_handler.hpp"

#include <dds/dds.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <map>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "raw_serdata.hpp"
#include "rbsim/interfaces.hpp"

namespace rbsim::node {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

constexpr std::uint32_t kDomain = 156;  // its own: graph_test has 145..154
constexpr std::string_view kStep = "rbsim_msgs/srv/Step";

std::vector<std::byte> bytes(std::initializer_list<int> v) {
  std::vector<std::byte> out;
  for (int b : v) out.push_back(static_cast<std::byte>(b));
  return out;
}

// A service of this process alone: tests of other processes may share the domain.
std::string unique_service(std::string_view name) {
  return "/service_test_" + std::to_string(::getpid()) + "/" + std::string(name);
}

using test::step_handler;

// Serves until `done` holds, at most `seconds` (the node's loop: serve, then sleep a 1 ms step).
template <class Done>
bool serve_until(ServiceServer& server, Done done, double seconds = 5.0) {
  const auto end =
      Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
  while (Clock::now() < end) {
    server.serve(step_handler, 16);
    if (done()) return true;
    server.wait(0.001);
  }
  return false;
}

struct Loopback : ::testing::Test {
  void SetUp() override {
    auto p = create_dds_participant(kDomain);
    ASSERT_TRUE(p.ok()) << p.error().message;
    participant.emplace(std::move(p.value()));
  }
  ServiceServer make_server(std::string_view service, const ServiceOptions& options = {}) {
    auto s = ServiceServer::create(*participant, service, kStep, options);
    EXPECT_TRUE(s.ok()) << s.error().message;
    return std::move(s.value());
  }
  ServiceClient make_client(std::string_view service, const ClientOptions& options = {}) {
    auto c = ServiceClient::create(*participant, service, kStep, options);
    EXPECT_TRUE(c.ok()) << c.error().message;
    return std::move(c.value());
  }
  std::optional<Participant> participant;
};

// A call from our client in another thread, served by the test's loop.
msgs::StepResponse call_step(ServiceServer& server, ServiceClient& client, std::uint32_t steps) {
  Bytes req;
  msgs::encode(msgs::StepRequest{steps}, req);
  Result<Bytes> reply = Error{"not called"};
  const std::uint64_t before = server.stats().answered;
  std::thread caller([&] { reply = client.call(req, 5.0); });
  serve_until(
      server, [&] { return server.stats().answered > before; }, 5.0);
  caller.join();
  msgs::StepResponse res;
  EXPECT_TRUE(reply.ok()) << reply.error().message;
  if (reply.ok()) {
    EXPECT_TRUE(msgs::decode(reply.value(), res).ok());
  }
  return res;
}

TEST(ServiceNames, TopicsAndTypesAreRmwCycloneddsOnes) {
  EXPECT_EQ(service_request_topic("/rbsim/pause"), "rq/rbsim/pauseRequest");
  EXPECT_EQ(service_reply_topic("/rbsim/pause"), "rr/rbsim/pauseReply");
  EXPECT_EQ(service_request_topic("/rbsim/get_parameters"), "rq/rbsim/get_parametersRequest");
  EXPECT_EQ(service_request_type("std_srvs/srv/Trigger"), "std_srvs::srv::dds_::Trigger_Request_");
  EXPECT_EQ(service_response_type("rcl_interfaces/srv/SetParametersAtomically"),
            "rcl_interfaces::srv::dds_::SetParametersAtomically_Response_");
}

// cdds_request_header_t {u64 guid; i64 seq} right after the encapsulation header, then the body.
TEST(ServiceSample, WrapPutsTheRequestHeaderBeforeTheBody) {
  Bytes body;
  msgs::encode(msgs::StepRequest{7}, body);  // 00 01 00 00 | 07 00 00 00
  Bytes sample;
  wrap_service_sample({0x0102030405060708ull, -2}, body, sample);
  EXPECT_EQ(sample, bytes({0,    1,    0,    0,    8,    7,    6,    5,    4, 3, 2, 1,
                           0xfe, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 7, 0, 0, 0}));
  Bytes back;
  auto h = unwrap_service_sample(sample, back);
  ASSERT_TRUE(h.ok()) << h.error().message;
  EXPECT_EQ(h.value(), (RequestHeader{0x0102030405060708ull, -2}));
  EXPECT_EQ(back, body);
}

// The body keeps its alignment: a float64 after a uint32 sits at body offset 8 both alone and
// after the 16-byte header (sample offset 24).
TEST(ServiceSample, BodyAlignmentIsUnchangedByTheHeader) {
  Bytes body, sample;
  msgs::encode(msgs::ApplyImpulseRequest{3, 1.5, 0, 0, 0}, body);
  wrap_service_sample({1, 1}, body, sample);
  double jx = 0;
  std::memcpy(&jx, sample.data() + 4 + 16 + 8, 8);
  EXPECT_EQ(jx, 1.5);
  ASSERT_EQ(sample.size(), body.size() + 16);
}

TEST(ServiceSample, UnwrapRefusesShortAndForeignSamples) {
  Bytes body;
  for (std::size_t n = 0; n < 20; ++n) {
    Bytes s(n, std::byte{0});
    if (n >= 2) s[1] = std::byte{1};
    EXPECT_FALSE(unwrap_service_sample(s, body).ok()) << n << " bytes";
  }
  Bytes big_endian = bytes({0, 0, 0, 0, 1, 2, 3, 4, 5, 6, 7, 8, 1, 2, 3, 4, 5, 6, 7, 8});  // CDR_BE
  EXPECT_FALSE(unwrap_service_sample(big_endian, body).ok());
}

TEST_F(Loopback, ServiceServerAnswersServiceClientWithItsHeaderBack) {
  const std::string name = unique_service("step");
  ServiceServer server = make_server(name);
  ServiceClient client = make_client(name);
  ASSERT_TRUE(client.wait_for_server(5.0).ok());
  Bytes req;
  msgs::encode(msgs::StepRequest{4}, req);
  auto seq = client.send(req);
  ASSERT_TRUE(seq.ok());
  const bool done = serve_until(server, [&] { return server.stats().answered == 1; });
  ASSERT_TRUE(done);
  RequestHeader got;
  Bytes reply;
  bool taken = false;
  for (int i = 0; i < 500 && !taken; ++i) taken = client.take_reply(got, reply) || !client.wait_reply(0.01);
  ASSERT_TRUE(taken);
  // The reply carries the request's header back unchanged: our client's id and the call's number.
  EXPECT_EQ(got, (RequestHeader{client.id(), seq.value()}));
  msgs::StepResponse res;
  ASSERT_TRUE(msgs::decode(reply, res).ok());
  EXPECT_TRUE(res.success);
  EXPECT_EQ(res.step, 40u);
  EXPECT_EQ(res.message, std::to_string(client.id()) + ":" + std::to_string(seq.value()));
}

// Each endpoint reports its GUID and instance handle, and carries the USER_DATA option after its
// clientid/serviceid.
TEST_F(Loopback, EndpointsReportIdsAndCarryUserData) {
  const std::string name = unique_service("ids");
  auto made_server = create_dds_server(*participant, name, kStep, {}, {"typehash=REQ;", ""});
  ASSERT_TRUE(made_server.ok()) << made_server.error().message;
  ServiceServer server = std::move(made_server.value());
  auto made_client = create_dds_client(*participant, name, kStep, {}, {"typehash=CLIENTREQ;", ""});
  ASSERT_TRUE(made_client.ok()) << made_client.error().message;
  ServiceClient client = std::move(made_client.value());
  ASSERT_TRUE(client.wait_for_server(5.0).ok());
  const EndpointId ids[] = {dds_request_reader(server), dds_reply_writer(server), dds_request_writer(client),
                            dds_reply_reader(client)};
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_NE(ids[i].instance_handle, 0u);
    for (std::size_t j = 0; j < i; ++j) EXPECT_NE(ids[i].guid, ids[j].guid);
  }
  EXPECT_EQ(client.id(), dds_request_writer(client).instance_handle);
  // What the server's reader sees of the client's writer (discovery data): USER_DATA.
  dds_entity_t topic_reader =
      dds_create_reader(dds_entity(*participant), DDS_BUILTIN_TOPIC_DCPSPUBLICATION, nullptr, nullptr);
  std::string user_data;
  for (int i = 0; i < 200 && user_data.empty(); ++i) {
    void* samples[16] = {};
    dds_sample_info_t infos[16];
    const int n = dds_read(topic_reader, samples, infos, 16, 16);
    for (int k = 0; k < n; ++k) {
      auto* e = static_cast<dds_builtintopic_endpoint_t*>(samples[k]);
      if (infos[k].valid_data && std::memcmp(e->key.v, ids[2].guid.data(), 16) == 0) {
        void* ud = nullptr;
        std::size_t sz = 0;
        if (dds_qget_userdata(e->qos, &ud, &sz) && ud != nullptr) {
          user_data.assign(static_cast<char*>(ud), sz);
          dds_free(ud);
        }
      }
    }
    if (n > 0) dds_return_loan(topic_reader, samples, n);
    if (user_data.empty()) std::this_thread::sleep_for(10ms);
  }
  dds_delete(topic_reader);
  EXPECT_TRUE(user_data.starts_with("clientid=")) << user_data;
  EXPECT_TRUE(user_data.ends_with(";typehash=CLIENTREQ;")) << user_data;
}

// Replies go to the client that asked: each client gets the replies to its own requests only.
TEST_F(Loopback, TwoClientsGetOnlyTheirOwnReplies) {
  const std::string name = unique_service("two");
  ServiceServer server = make_server(name);
  ServiceClient a = make_client(name), b = make_client(name);
  ASSERT_TRUE(a.wait_for_server(5.0).ok());
  ASSERT_TRUE(b.wait_for_server(5.0).ok());
  ASSERT_NE(a.id(), b.id());
  std::map<std::int64_t, std::uint32_t> sent_a, sent_b;
  Bytes req;
  for (std::uint32_t i = 1; i <= 5; ++i) {
    msgs::encode(msgs::StepRequest{i}, req);
    sent_a[a.send(req).value()] = i;
    msgs::encode(msgs::StepRequest{100 + i}, req);
    sent_b[b.send(req).value()] = 100 + i;
  }
  ASSERT_TRUE(serve_until(server, [&] { return server.stats().answered == 10; }));
  for (auto* c : {&a, &b}) {
    auto& sent = c == &a ? sent_a : sent_b;
    std::size_t got = 0;
    RequestHeader h;
    Bytes reply;
    for (int i = 0; i < 500 && got < sent.size(); ++i) {
      if (!c->take_reply(h, reply)) {
        c->wait_reply(0.01);
        continue;
      }
      ++got;
      EXPECT_EQ(h.guid, c->id());
      ASSERT_TRUE(sent.contains(h.seq));
      msgs::StepResponse res;
      ASSERT_TRUE(msgs::decode(reply, res).ok());
      EXPECT_EQ(res.step, 10ull * sent[h.seq]);
    }
    EXPECT_EQ(got, sent.size());
    EXPECT_FALSE(c->take_reply(h, reply));  // nothing else: the other's replies were skipped
  }
}

// A client that disappears between its request and the reply gets none, and the server does not
// wait for it.
TEST_F(Loopback, ServerDropsTheReplyOfAVanishedClientWithoutStalling) {
  const std::string name = unique_service("gone");
  ServiceServer server = make_server(name);
  {
    ServiceClient client = make_client(name);
    ASSERT_TRUE(client.wait_for_server(5.0).ok());
    Bytes req;
    msgs::encode(msgs::StepRequest{1}, req);
    ASSERT_TRUE(client.send(req).ok());
    ASSERT_TRUE(server.wait(5.0));  // queued, not yet served
  }
  // The client's endpoints are gone once its request writer is unmatched.
  for (int i = 0; i < 500; ++i) {
    const auto t0 = Clock::now();
    server.serve(step_handler, 16);
    EXPECT_LT(Clock::now() - t0, 50ms);
    if (server.stats().client_gone + server.stats().answered > 0) break;
    std::this_thread::sleep_for(10ms);
  }
  const ServiceStats s = server.stats();
  EXPECT_EQ(s.client_gone, 1u);
  EXPECT_EQ(s.answered, 0u);
  EXPECT_EQ(s.pending, 0u);
}

// A raw DDS endpoint on a service topic (what a hostile or broken client can send).
struct RawWriter {
  RawWriter(dds_entity_t participant, const std::string& topic_name, const std::string& type,
            const std::string& user_data) {
    ddsi_sertype* st = make_raw_sertype(type.c_str());
    topic = dds_create_topic_sertype(participant, topic_name.c_str(), &st, nullptr, nullptr, nullptr);
    sertype = st;
    dds_qos_t* q = dds_create_qos();
    dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
    dds_qset_history(q, DDS_HISTORY_KEEP_ALL, 0);
    dds_qset_userdata(q, user_data.data(), user_data.size());
    writer = dds_create_writer(participant, topic, q, nullptr);
    dds_delete_qos(q);
  }
  ~RawWriter() {
    dds_delete(writer);
    dds_delete(topic);
  }
  void write(std::span<const std::byte> b) {
    EXPECT_GE(dds_writecdr(writer, make_raw_serdata(sertype, b)), 0);
  }
  bool matched() const {
    dds_publication_matched_status_t st{};
    dds_get_publication_matched_status(writer, &st);
    return st.current_count > 0;
  }
  dds_entity_t topic = 0, writer = 0;
  const ddsi_sertype* sertype = nullptr;
};

// A client that says it has a clientid but whose reply reader never shows up: the reply waits
// (retried at each serve()) for the match timeout, then is dropped; serve() never blocks.
TEST_F(Loopback, ReplyToAClientWithoutItsReplyReaderIsDroppedAfterTheMatchTimeout) {
  const std::string name = unique_service("unmatched");
  ServiceOptions so;
  so.client_match_timeout_s = 0.2;
  ServiceServer server = make_server(name, so);
  RawWriter raw(dds_entity(*participant), service_request_topic(name), service_request_type(kStep),
                "clientid=nobody;");
  for (int i = 0; i < 500 && !raw.matched(); ++i) std::this_thread::sleep_for(10ms);
  ASSERT_TRUE(raw.matched());
  Bytes body, sample;
  msgs::encode(msgs::StepRequest{2}, body);
  wrap_service_sample({42, 1}, body, sample);
  raw.write(sample);
  const auto t0 = Clock::now();
  auto longest = Clock::duration::zero();
  while (Clock::now() - t0 < 3s) {
    const auto s0 = Clock::now();
    server.serve(step_handler, 16);
    longest = std::max(longest, Clock::now() - s0);
    if (server.stats().client_unmatched > 0) break;
    std::this_thread::sleep_for(5ms);
  }
  const ServiceStats s = server.stats();
  EXPECT_EQ(s.client_unmatched, 1u);
  EXPECT_EQ(s.answered, 0u);
  EXPECT_GE(Clock::now() - t0, 150ms);  // it did wait for the reader, about the timeout
  EXPECT_LT(longest, 50ms);
}

// typed_handler: a request that decodes is answered by the typed function; one that does not gets
// the malformed reply (here: success false with the decoder's error), or none.
TEST(ServiceTypedHandler, DecodesRequestsAndAnswersMalformedOnes) {
  const ServiceServer::Handler h = typed_handler<msgs::StepRequest, msgs::StepResponse>(
      [](const RequestHeader& header, const msgs::StepRequest& r) {
        return msgs::StepResponse{true, "seq " + std::to_string(header.seq), 2ull * r.steps};
      },
      [](const Error& e) {
        return std::optional<msgs::StepResponse>(msgs::StepResponse{false, e.message, 0});
      });
  Bytes req, reply;
  msgs::encode(msgs::StepRequest{21}, req);
  ASSERT_TRUE(h({5, 9}, req, reply));
  msgs::StepResponse res;
  ASSERT_TRUE(msgs::decode(reply, res).ok());
  EXPECT_EQ(res, (msgs::StepResponse{true, "seq 9", 42}));
  req.resize(6);  // the u32 cut short
  ASSERT_TRUE(h({5, 10}, req, reply));
  ASSERT_TRUE(msgs::decode(reply, res).ok());
  EXPECT_FALSE(res.success);
  EXPECT_NE(res.message.find("rbsim_msgs/srv/Step request"), std::string::npos) << res.message;
  const ServiceServer::Handler silent =
      typed_handler<msgs::GetParametersRequest, msgs::GetParametersResponse>(
          [](const RequestHeader&, const msgs::GetParametersRequest&) {
            return msgs::GetParametersResponse{};
          },
          [](const Error&) { return std::optional<msgs::GetParametersResponse>(); });
  EXPECT_FALSE(silent({5, 11}, req, reply));
}

// Hostile samples: not CDR, shorter than the header, over the size limit, a truncated body. None
// crashes; the first three are dropped and counted, the last one gets an unsuccessful reply.
TEST_F(Loopback, HostileRequestsAreCountedOrRefused) {
  const std::string name = unique_service("hostile");
  ServiceOptions so;
  so.max_request_bytes = 1024;
  ServiceServer server = make_server(name, so);
  RawWriter raw(dds_entity(*participant), service_request_topic(name), service_request_type(kStep), "");
  ServiceClient witness = make_client(name);  // so the reply writer has a reader to match
  for (int i = 0; i < 500 && !raw.matched(); ++i) std::this_thread::sleep_for(10ms);
  ASSERT_TRUE(raw.matched());
  raw.write(bytes({1, 2}));
  raw.write(bytes({0, 0, 0, 0, 1, 2, 3, 4, 5, 6, 7, 8, 1, 2, 3, 4, 5, 6, 7, 8}));  // big endian
  raw.write(bytes({0, 1, 0, 0, 1, 2, 3, 4, 5, 6, 7, 8, 1, 2, 3}));                 // header cut short
  raw.write(Bytes(2048, std::byte{0}));
  raw.write(bytes({0, 1, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 9, 0, 0, 0, 0, 0, 0, 0, 7, 0}));  // steps cut short
  ASSERT_TRUE(serve_until(server, [&] {
    const ServiceStats s = server.stats();
    return s.malformed + s.dropped_large + s.answered + s.client_unmatched == 5;
  }));
  const ServiceStats s = server.stats();
  EXPECT_EQ(s.received, 5u);
  EXPECT_EQ(s.malformed, 3u);
  EXPECT_EQ(s.dropped_large, 1u);
  // No clientid: the server cannot tell whether a reader is there and answers (rmw's rule).
  EXPECT_EQ(s.answered, 1u);
}

// 10,000 requests as fast as a client sends them, the server serving 16 per 1 ms step: the queue
// never exceeds its limit, every received request is accounted for, each serve() stays short,
// the client's replies are its own, and a call afterwards is answered.
TEST_F(Loopback, FloodOfRequestsIsBoundedAndTheServerStaysResponsive) {
  const std::string name = unique_service("flood");
  ServiceOptions so;
  so.queue_limit = 32;
  ServiceServer server = make_server(name, so);
  ServiceClient client = make_client(name);
  ASSERT_TRUE(client.wait_for_server(5.0).ok());
  std::atomic<bool> sending{true};
  std::thread flood([&] {
    Bytes req;
    for (std::uint32_t i = 0; i < 10000; ++i) {
      msgs::encode(msgs::StepRequest{i}, req);
      (void)client.send(req);
    }
    sending = false;
  });
  const auto t0 = Clock::now();
  auto longest = Clock::duration::zero();
  std::size_t max_queued = 0;
  while (Clock::now() - t0 < 20s) {
    const auto s0 = Clock::now();
    server.serve(step_handler, 16);
    longest = std::max(longest, Clock::now() - s0);
    const ServiceStats s = server.stats();
    max_queued = std::max(max_queued, s.queued);
    if (!sending && s.queued == 0 && Clock::now() - t0 > 200ms) break;
    std::this_thread::sleep_for(1ms);
  }
  flood.join();
  EXPECT_LT(Clock::now() - t0, 20s);
  ServiceStats s = server.stats();
  EXPECT_LE(max_queued, so.queue_limit);
  EXPECT_GT(s.received, 0u);
  EXPECT_EQ(s.received, s.answered + s.unanswered + s.dropped_full + s.dropped_large + s.malformed +
                            s.client_unmatched + s.client_gone + s.write_failed + s.pending + s.queued);
  EXPECT_EQ(s.malformed + s.dropped_large + s.write_failed, 0u);
  EXPECT_LT(longest, 100ms) << "one serve() of 16 requests";
  // The replies that came back are to this client's requests, numbered as it sent them.
  RequestHeader h;
  Bytes reply;
  std::size_t replies = 0;
  while (client.take_reply(h, reply)) {
    msgs::StepResponse res;
    ASSERT_TRUE(msgs::decode(reply, res).ok());
    EXPECT_EQ(h.guid, client.id());
    EXPECT_EQ(res.step, 10ull * static_cast<std::uint64_t>(h.seq - 1));  // seq 1 carried steps 0
    ++replies;
  }
  EXPECT_GT(replies, 0u);
  std::printf("flood: received %llu, answered %llu, dropped (queue full) %llu, replies taken %zu\n",
              static_cast<unsigned long long>(s.received), static_cast<unsigned long long>(s.answered),
              static_cast<unsigned long long>(s.dropped_full), replies);
  const msgs::StepResponse after = call_step(server, client, 3);
  EXPECT_TRUE(after.success);
  EXPECT_EQ(after.step, 30u);
}

}  // namespace
}  // namespace rbsim::node
