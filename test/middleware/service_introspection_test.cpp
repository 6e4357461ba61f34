// Service introspection (REP 2012) of ServiceSet on every backend (backends.hpp): off by default
// (no event, no publisher), metadata (REQUEST_RECEIVED and RESPONSE_SENT per call, empty request
// and response, the client's id and sequence number), contents (the request and the response
// decoded equal to what was sent and answered), off again.
#include <algorithm>

#include "backends.hpp"
#include "rbsim/interfaces.hpp"
#include "rbsim/service.hpp"
#include "rbsim/service_event.hpp"
#include "rbsim/service_set.hpp"

namespace rbsim::node::test {
namespace {

constexpr std::string_view kStep = msgs::StepRequest::kService;

using ServiceIntrospection = Backends;

struct Event {
  msgs::ServiceEventInfo info;
  Bytes request, response;
};

// The events on `sub` until `count` came (bounded), decoded.
std::vector<Event> take_events(Subscription& sub, const msgs::ServiceEventCodec& codec, std::size_t count) {
  std::vector<Event> out;
  Received r;
  eventually([&] {
    while (sub.take(r)) {
      Event e;
      const Status st = codec.decode(r.cdr, e.info, e.request, e.response);
      EXPECT_TRUE(st) << (st ? "" : st.error().message);
      out.push_back(std::move(e));
    }
    return out.size() >= count;
  });
  return out;
}

TEST_P(ServiceIntrospection, OffMetadataContentsOff) {
  Participant server_side = participant("server");
  Participant client_side = participant("client");
  const std::string leaf = name("step");
  const std::string node = leaf.substr(0, leaf.rfind('/'));
  ServiceSet set;
  // step N answers step 10 * N, with a message of odd length so the uint64 after it moves.
  ASSERT_TRUE(set.add(server_side, node, "step", kStep,
                      typed_handler<msgs::StepRequest, msgs::StepResponse>(
                          [](const RequestHeader&, const msgs::StepRequest& req) {
                            return msgs::StepResponse{true, std::string(req.steps, 'm'), 10ull * req.steps};
                          },
                          [](const Error&) { return std::optional<msgs::StepResponse>(); })));
  set.start();
  EXPECT_EQ(set.introspection(), IntrospectionState::Off);

  Result<msgs::ServiceEventCodec> codec = msgs::ServiceEventCodec::create(kStep);
  ASSERT_TRUE(codec);
  const std::string topic = leaf + "/_service_event";
  auto sub =
      Subscription::create(client_side, RawTopic{topic, "rbsim_msgs/srv/Step_Event"}, service_event_qos());
  auto client = ServiceClient::create(client_side, leaf, kStep);
  ASSERT_TRUE(sub.ok() && client.ok());
  ASSERT_TRUE(client->wait_for_server(kPatience).ok());
  const auto call = [&](std::uint32_t steps) {
    Bytes req;
    msgs::encode(msgs::StepRequest{steps}, req);
    Result<Bytes> reply = client->call(req, kPatience);
    EXPECT_TRUE(reply.ok());
  };

  // Off: no publisher to match, nothing published.
  call(1);
  EXPECT_EQ(sub->matched(), 0);
  Received r;
  EXPECT_FALSE(sub->take(r));
  EXPECT_EQ(set.events_published(), 0u);
  // ... and no publisher on the graph (the test's subscription is there).
  const auto publishers = [&] {
    std::size_t n = 0;
    for (const MemoryNetwork::Node& node_entry : network_->graph()) {
      for (const MemoryNetwork::Endpoint& e : node_entry.endpoints)
        n += e.kind == MemoryNetwork::Endpoint::Kind::Publisher && e.name == topic;
    }
    return n;
  };
  if (memory()) {
    EXPECT_EQ(publishers(), 0u);
  }

  // Metadata: two events per call, in order, with the call's id and sequence number, no contents.
  ASSERT_TRUE(set.configure_introspection(server_side, IntrospectionState::Metadata));
  ASSERT_TRUE(eventually([&] { return sub->matched() == 1; }));
  if (memory()) {
    EXPECT_EQ(publishers(), 1u);
  }
  call(2);
  call(3);
  std::vector<Event> events = take_events(*sub, codec.value(), 4);
  ASSERT_EQ(events.size(), 4u);
  const std::array<std::uint8_t, 16> gid = client_gid(RequestHeader{client->id(), 0});
  EXPECT_NE(gid, (std::array<std::uint8_t, 16>{}));
  for (std::size_t i = 0; i < 4; ++i) {
    SCOPED_TRACE("event " + std::to_string(i));
    EXPECT_EQ(events[i].info.event_type,
              i % 2 == 0 ? msgs::ServiceEventType::RequestReceived : msgs::ServiceEventType::ResponseSent);
    EXPECT_EQ(events[i].info.sequence_number, static_cast<std::int64_t>(2 + i / 2));  // the 2nd and 3rd calls
    EXPECT_EQ(events[i].info.client_gid, gid);
    EXPECT_GT(events[i].info.stamp.sec, 1'600'000'000);  // the system clock
    EXPECT_TRUE(events[i].request.empty());
    EXPECT_TRUE(events[i].response.empty());
  }

  // Contents: the request as sent, the response as answered.
  ASSERT_TRUE(set.configure_introspection(server_side, IntrospectionState::Contents));
  call(5);
  events = take_events(*sub, codec.value(), 2);
  ASSERT_EQ(events.size(), 2u);
  msgs::StepRequest req;
  ASSERT_TRUE(msgs::decode(events[0].request, req));
  EXPECT_EQ(req.steps, 5u);
  EXPECT_TRUE(events[0].response.empty());
  msgs::StepResponse res;
  ASSERT_TRUE(msgs::decode(events[1].response, res));
  EXPECT_EQ(res, (msgs::StepResponse{true, "mmmmm", 50}));
  EXPECT_TRUE(events[1].request.empty());
  EXPECT_EQ(events[1].info.sequence_number, 4);
  EXPECT_EQ(set.events_published(), 6u);
  EXPECT_EQ(set.events_failed(), 0u);

  // Off again: the publishers go, nothing more is published.
  ASSERT_TRUE(set.configure_introspection(server_side, IntrospectionState::Off));
  call(6);
  ASSERT_TRUE(eventually([&] { return sub->matched() == 0; }));
  EXPECT_FALSE(sub->take(r));
  EXPECT_EQ(set.events_published(), 6u);
  if (memory()) {
    EXPECT_EQ(publishers(), 0u);
  }
}

TEST(IntrospectionState, WordsOfTheRos2Demos) {
  for (const IntrospectionState s :
       {IntrospectionState::Off, IntrospectionState::Metadata, IntrospectionState::Contents}) {
    EXPECT_EQ(parse_introspection_state(to_string(s)), s);
  }
  EXPECT_EQ(to_string(IntrospectionState::Off), "disabled");
  EXPECT_FALSE(parse_introspection_state("off"));
  EXPECT_FALSE(parse_introspection_state("CONTENTS"));
  const QosSpec q = service_event_qos();
  EXPECT_FALSE(q.transient_local);
  EXPECT_FALSE(q.keep_all);
  EXPECT_EQ(q.depth, 10);
}

INSTANTIATE_TEST_SUITE_P(Seam, ServiceIntrospection, ::testing::Values("memory", "dds"), backend_name);

}  // namespace
}  // namespace rbsim::node::test
