// The bridge's Relay (node/bridge) over the in-memory middleware (rbsim/memory_middleware.hpp): a
// node's run in this process, every topic of its namespace handed on unchanged. test/e2e runs the
// bridge as its own process over DDS.
#include <gtest/gtest.h>

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "control_test_util.hpp"
#include "rbsim/dds_sink.hpp"
#include "rbsim/memory_middleware.hpp"
#include "rbsim/relay.hpp"

namespace rbsim::bridge {

using namespace node;
namespace {

constexpr std::int64_t kSteps = 25;

Participant participant(const std::shared_ptr<MemoryNetwork>& network, const std::string& name) {
  Result<Participant> p = create_memory_participant(network, NodeName{"/", name});
  if (!p) throw std::runtime_error(p.error().message);
  return std::move(p.value());
}

// What each topic carried, in order.
using Payloads = std::map<std::string, std::vector<Bytes>>;

// Publishes the control scene's run in namespace `ns` through a DdsSink, as rbsim node does, and
// returns what it published per topic (the encoder's bytes: StepMessages shared with the sink).
// `keep` (if any) keeps the node's publishers: a writer's transient-local history goes with it.
Payloads run_node(const Participant& node, const std::string& ns,
                  msgs::TopicSet topics = msgs::default_topics(), std::unique_ptr<DdsSink>* keep = nullptr) {
  const Scene scene = test::control_scene();
  NodeOptions options;
  options.ns = ns;
  options.topics = topics;
  options.messages = std::make_shared<msgs::StepMessages>(scene, ns);
  Result<std::unique_ptr<DdsSink>> sink = DdsSink::create(node, options);
  if (!sink) throw std::runtime_error(sink.error().message);
  Result<Driver> driver = Driver::create(scene);
  if (!driver) throw std::runtime_error(driver.error().message);
  driver.value().add(*sink.value());
  // A second sink sees the same steps and keeps what the DdsSink sent of each.
  struct Copy final : Sink {
    std::shared_ptr<msgs::StepMessages> messages;
    const NodeOptions* options;
    Payloads out;
    Status begin(const Scene&, const World& world) override {
      for (const msgs::TopicId id : msgs::topic_ids(options->topics))
        if (!msgs::topic(id).per_step) keep(id, world);
      return write(world);
    }
    Status write(const World& world) override {
      for (const msgs::TopicId id : msgs::topic_ids(options->topics))
        if (msgs::topic(id).per_step) keep(id, world);
      return Ok{};
    }
    Status finish() override { return Ok{}; }
    void keep(msgs::TopicId id, const World& world) {
      const Bytes& b = messages->get(id, world);
      out[msgs::topic_name(msgs::topic(id), options->ns)].push_back(b);
    }
  } copy;
  copy.messages = options.messages;
  copy.options = &options;
  driver.value().add(copy);
  if (Status st = driver.value().begin(); !st) throw std::runtime_error(st.error().message);
  DriverOptions o;
  o.steps = kSteps;
  if (Result<PassEnd> end = driver.value().run(o); !end) throw std::runtime_error(end.error().message);
  if (keep != nullptr) *keep = std::move(sink.value());
  return copy.out;
}

TEST(Relay, HandsOnEveryTopicOfItsNamespaceUnchanged) {
  auto network = std::make_shared<MemoryNetwork>();
  Participant node = participant(network, "rbsim");
  Participant bridge = participant(network, "rbsim_bridge");
  Result<std::unique_ptr<Relay>> relay = Relay::create(bridge, "rbsim");
  ASSERT_TRUE(relay.ok()) << relay.error().message;
  // Another namespace's node on the same network: none of its samples reach this relay (it
  // publishes neither /tf nor /clock, which live at the root for every namespace).
  Participant other = participant(network, "other");
  msgs::TopicSet namespaced = msgs::default_topics();
  namespaced.reset(static_cast<std::size_t>(msgs::TopicId::Tf));
  namespaced.reset(static_cast<std::size_t>(msgs::TopicId::Clock));
  (void)run_node(other, "elsewhere", namespaced);
  const Payloads sent = run_node(node, "rbsim");

  std::uint64_t expected = 0;
  for (const auto& [topic, messages] : sent) {
    expected += messages.size();
    ASSERT_LE(messages.size(), static_cast<std::size_t>(Relay::kDepth))
        << topic << ": within its reader's depth";
  }
  Payloads got;
  for (int i = 0; i < 1000 && relay.value()->received() < expected; ++i) {
    Result<std::uint64_t> n =
        relay.value()->poll(1'000'000, [&](const msgs::TopicSpec& spec, std::span<const std::byte> cdr) {
          got[msgs::topic_name(spec, "rbsim")].emplace_back(cdr.begin(), cdr.end());
        });
    ASSERT_TRUE(n.ok()) << n.error().message;
  }
  EXPECT_EQ(relay.value()->received(), expected);
  EXPECT_EQ(got, sent);
  EXPECT_EQ(relay.value()->lost(), 0u);
}

TEST(Relay, StartedAfterTheNodeStillGetsTheSceneDescription) {
  auto network = std::make_shared<MemoryNetwork>();
  Participant node = participant(network, "rbsim");
  std::unique_ptr<DdsSink> publishing;  // the node goes on (paused, say): its publishers live
  const Payloads sent = run_node(node, "rbsim", msgs::default_topics(), &publishing);
  Participant bridge = participant(network, "rbsim_bridge");
  Result<std::unique_ptr<Relay>> relay = Relay::create(bridge, "rbsim");
  ASSERT_TRUE(relay.ok()) << relay.error().message;
  Payloads got;
  for (int i = 0; i < 100 && got.count("/rbsim/scene") == 0; ++i) {
    ASSERT_TRUE(relay.value()
                    ->poll(1'000'000,
                           [&](const msgs::TopicSpec& spec, std::span<const std::byte> cdr) {
                             got[msgs::topic_name(spec, "rbsim")].emplace_back(cdr.begin(), cdr.end());
                           })
                    .ok());
  }
  ASSERT_EQ(got.count("/rbsim/scene"), 1u);
  EXPECT_EQ(got.at("/rbsim/scene"), sent.at("/rbsim/scene")) << "the latched scene description, once";
  EXPECT_EQ(got.count("/rbsim/body_states"), 0u)
      << "volatile per-step samples are not replayed to a late joiner";
}

}  // namespace
}  // namespace rbsim::bridge
