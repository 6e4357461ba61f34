// ServiceServer and ServiceClient on every backend (backends.hpp): a call answered to its caller
// only, readiness, the server's counters and its arrival callback.
#include <atomic>
#include <map>

#include "backends.hpp"
#include "rbsim/interfaces.hpp"
#include "rbsim/service.hpp"

namespace rbsim::node::test {
namespace {

constexpr std::string_view kStep = msgs::StepRequest::kService;

// steps -> step = 10 * steps, message "<guid>:<seq>" of the request header.
bool step_handler(const RequestHeader& h, std::span<const std::byte> request, Bytes& reply) {
  msgs::StepRequest req;
  msgs::StepResponse res;
  if (Status st = msgs::decode(request, req); st) {
    res.success = true;
    res.step = 10ull * req.steps;
    res.message = std::to_string(h.guid) + ":" + std::to_string(h.seq);
  }
  msgs::encode(res, reply);
  return true;
}

Bytes step_request(std::uint32_t steps) {
  Bytes req;
  msgs::encode(msgs::StepRequest{steps}, req);
  return req;
}

// Serves until `done` holds (bounded).
template <class Done>
bool serve_until(ServiceServer& server, Done done, double seconds = kPatience) {
  return eventually(
      [&] {
        server.serve(step_handler, 16);
        if (done()) return true;
        server.wait(0.001);
        return false;
      },
      seconds);
}

using ServiceServerSeam = Backends;
using ServiceClientSeam = Backends;

// Two clients' calls: each gets the replies to its own requests only, their headers carrying its
// id and sequence numbers.
TEST_P(ServiceServerSeam, RepliesGoToTheCallingClientOnly) {
  Participant p = participant();
  const std::string service = name("step");
  auto server = ServiceServer::create(p, service, kStep);
  auto a = ServiceClient::create(p, service, kStep);
  auto b = ServiceClient::create(p, service, kStep);
  ASSERT_TRUE(server.ok() && a.ok() && b.ok());
  ASSERT_TRUE(a->wait_for_server(kPatience).ok());
  ASSERT_TRUE(b->wait_for_server(kPatience).ok());
  EXPECT_NE(a->id(), b->id());
  std::map<std::int64_t, std::uint32_t> sent_a, sent_b;
  for (std::uint32_t i = 1; i <= 3; ++i) {
    sent_a[a->send(step_request(i)).value()] = i;
    sent_b[b->send(step_request(100 + i)).value()] = 100 + i;
  }
  ASSERT_TRUE(serve_until(server.value(), [&] { return server->stats().answered == 6; }));
  for (auto* c : {&a.value(), &b.value()}) {
    auto& sent = c == &a.value() ? sent_a : sent_b;
    std::size_t got = 0;
    RequestHeader h;
    Bytes reply;
    ASSERT_TRUE(eventually([&] {
      while (c->take_reply(h, reply)) {
        ++got;
        EXPECT_EQ(h.guid, c->id());
        EXPECT_TRUE(sent.contains(h.seq));
        msgs::StepResponse res;
        EXPECT_TRUE(msgs::decode(reply, res).ok());
        EXPECT_EQ(res.step, 10ull * sent[h.seq]);
        EXPECT_EQ(res.message, std::to_string(c->id()) + ":" + std::to_string(h.seq));
      }
      if (got < sent.size()) c->wait_reply(0.01);
      return got >= sent.size();
    }));
    EXPECT_EQ(got, sent.size());
    EXPECT_FALSE(c->take_reply(h, reply));
  }
  const ServiceStats s = server->stats();
  EXPECT_EQ(s.received, 6u);
  EXPECT_EQ(s.queued, 0u);
}

// call(): the reply to that request, within its timeout; a client with no server is not ready.
TEST_P(ServiceClientSeam, CallWaitsForItsReplyAndServerReadyNeedsAServer) {
  Participant p = participant();
  const std::string service = name("step");
  auto client = ServiceClient::create(p, service, kStep);
  ASSERT_TRUE(client.ok());
  EXPECT_FALSE(client->server_ready());
  EXPECT_FALSE(client->wait_for_server(0.05).ok());
  auto server = ServiceServer::create(p, service, kStep);
  ASSERT_TRUE(server.ok());
  ASSERT_TRUE(client->wait_for_server(kPatience).ok());
  EXPECT_TRUE(client->server_ready());
  EXPECT_EQ(server->service(), service);
  std::atomic<bool> stop{false};
  std::thread serving([&] {
    while (!stop) {
      server->serve(step_handler);
      server->wait(0.005);
    }
  });
  Result<Bytes> reply = client->call(step_request(4), kPatience);
  stop = true;
  serving.join();
  ASSERT_TRUE(reply.ok()) << reply.error().message;
  msgs::StepResponse res;
  ASSERT_TRUE(msgs::decode(reply.value(), res).ok());
  EXPECT_EQ(res.step, 40u);
  EXPECT_FALSE(client->send(Bytes{std::byte{0}}).ok()) << "a request shorter than a CDR header";
}

// The server's counters as the DDS server keeps them: a full queue drops, a large request drops,
// a handler may choose not to answer; on_arrival is called for each queued request.
TEST_P(ServiceServerSeam, CountsDropsAndUnansweredAndCallsOnArrival) {
  Participant p = participant();
  const std::string service = name("step");
  std::atomic<int> arrivals{0};
  ServiceOptions so;
  so.queue_limit = 2;
  so.max_request_bytes = 16 + 8;  // the header and a StepRequest (4 + 4), nothing longer
  so.on_arrival = [&] { ++arrivals; };
  auto server = ServiceServer::create(p, service, kStep, so);
  auto client = ServiceClient::create(p, service, kStep);
  ASSERT_TRUE(server.ok() && client.ok());
  ASSERT_TRUE(client->wait_for_server(kPatience).ok());
  Bytes large = step_request(1);
  large.resize(large.size() + 8);
  ASSERT_TRUE(client->send(large).ok());
  for (std::uint32_t i = 0; i < 4; ++i) ASSERT_TRUE(client->send(step_request(i)).ok());
  ASSERT_TRUE(eventually([&] { return server->stats().received == 5; }));
  ServiceStats s = server->stats();
  EXPECT_EQ(s.dropped_large, 1u);
  EXPECT_EQ(s.dropped_full, 2u);
  EXPECT_EQ(s.queued, 2u);
  EXPECT_EQ(arrivals.load(), 2);
  EXPECT_TRUE(server->wait(0.0));
  const std::size_t handled =
      server->serve([](const RequestHeader&, std::span<const std::byte>, Bytes&) { return false; });
  EXPECT_EQ(handled, 2u);
  s = server->stats();
  EXPECT_EQ(s.unanswered, 2u);
  EXPECT_EQ(s.answered, 0u);
  EXPECT_EQ(s.queued, 0u);
  EXPECT_FALSE(server->wait(0.0));
}

// typed_handler decodes the request and encodes the answer; a request that does not decode gets
// on_malformed's reply.
TEST_P(ServiceServerSeam, TypedHandlerAnswersAndRepliesToMalformedRequests) {
  Participant p = participant();
  const std::string service = name("step");
  auto server = ServiceServer::create(p, service, kStep);
  auto client = ServiceClient::create(p, service, kStep);
  ASSERT_TRUE(server.ok() && client.ok());
  ASSERT_TRUE(client->wait_for_server(kPatience).ok());
  const auto handler = typed_handler<msgs::StepRequest, msgs::StepResponse>(
      [](const RequestHeader&, const msgs::StepRequest& req) {
        return msgs::StepResponse{true, "ok", req.steps + 1u};
      },
      [](const Error&) {
        return std::optional<msgs::StepResponse>(msgs::StepResponse{false, "malformed", 0});
      });
  Bytes truncated = step_request(1);
  truncated.resize(6);
  ASSERT_TRUE(client->send(step_request(41)).ok());
  ASSERT_TRUE(client->send(truncated).ok());
  ASSERT_TRUE(eventually([&] {
    server->serve(handler);
    return server->stats().answered == 2;
  }));
  std::vector<msgs::StepResponse> got;
  RequestHeader h;
  Bytes reply;
  ASSERT_TRUE(eventually([&] {
    while (client->take_reply(h, reply)) {
      msgs::StepResponse res;
      EXPECT_TRUE(msgs::decode(reply, res).ok());
      got.push_back(res);
    }
    return got.size() == 2;
  }));
  EXPECT_EQ(got[0].step, 42u);
  EXPECT_FALSE(got[1].success);
  EXPECT_EQ(got[1].message, "malformed");
}

INSTANTIATE_TEST_SUITE_P(Seam, ServiceServerSeam, ::testing::Values("memory", "dds"), backend_name);
INSTANTIATE_TEST_SUITE_P(Seam, ServiceClientSeam, ::testing::Values("memory", "dds"), backend_name);

}  // namespace
}  // namespace rbsim::node::test
