// Publisher, Subscription, Received and WaitSet on every backend (backends.hpp): matching,
// delivery with the writer's id, time and QoS, durability for late joiners, wait sets.
#include <algorithm>

#include "backends.hpp"

namespace rbsim::node::test {
namespace {

const msgs::TopicSpec& clock_spec() {
  return msgs::topic(msgs::TopicId::Clock);
}

QosSpec volatile_keep_last(std::int32_t depth) {
  return QosSpec{false, false, depth};
}
QosSpec transient_keep_last(std::int32_t depth) {
  return QosSpec{true, false, depth};
}

using PublisherSeam = Backends;
using SubscriptionSeam = Backends;
using WaitSetSeam = Backends;

// A sample arrives as published, with its writer's id, a source time and the writer's offered QoS.
TEST_P(PublisherSeam, PublishedSampleArrivesWithWriterTimeAndOfferedQos) {
  Participant p = participant();
  const std::string topic = name("clock");
  auto pub = Publisher::create(p, clock_spec(), topic, transient_keep_last(3));
  ASSERT_TRUE(pub.ok()) << pub.error().message;
  auto sub = Subscription::create(p, clock_spec(), topic, volatile_keep_last(10));
  ASSERT_TRUE(sub.ok()) << sub.error().message;
  auto waitset = WaitSet::create(p);
  ASSERT_TRUE(waitset.ok());
  waitset->attach(sub.value());
  ASSERT_TRUE(pub->wait_for_subscribers(1, nullptr));
  EXPECT_EQ(pub->matched(), 1);
  EXPECT_TRUE(eventually([&] { return sub->matched() == 1; }));
  EXPECT_EQ(pub->ros_topic(), topic);
  EXPECT_EQ(sub->ros_topic(), topic);
  EXPECT_EQ(&sub->spec(), &clock_spec());

  ASSERT_TRUE(pub->publish(clock_cdr(7)).ok());
  ASSERT_TRUE(pub->publish(clock_cdr(8)).ok());
  Received a, b;
  ASSERT_TRUE(take_within(waitset.value(), sub.value(), a));
  ASSERT_TRUE(take_within(waitset.value(), sub.value(), b));
  EXPECT_TRUE(std::ranges::equal(a.cdr, clock_cdr(7)));
  EXPECT_TRUE(std::ranges::equal(b.cdr, clock_cdr(8)));
  EXPECT_TRUE(a.held);
  EXPECT_GT(a.source_time_ns, 0);
  EXPECT_LE(a.source_time_ns, b.source_time_ns);
  EXPECT_EQ(a.writer, b.writer);
  EXPECT_NE(a.writer, (std::array<std::uint8_t, 16>{}));
  EXPECT_TRUE(a.offered.transient_local);
  EXPECT_FALSE(a.offered.keep_all);
  EXPECT_EQ(a.offered.depth, 3);
  EXPECT_TRUE(pub->flush(5.0).ok());
  EXPECT_EQ(sub->lost(), 0u);
}

// Two publishers on one topic: the samples tell them apart by their writer ids.
TEST_P(PublisherSeam, EachWriterHasItsOwnStableId) {
  Participant p = participant();
  const std::string topic = name("clock");
  auto sub = Subscription::create(p, clock_spec(), topic, volatile_keep_last(10));
  auto one = Publisher::create(p, clock_spec(), topic, volatile_keep_last(10));
  auto two = Publisher::create(p, clock_spec(), topic, volatile_keep_last(10));
  auto waitset = WaitSet::create(p);
  ASSERT_TRUE(sub.ok() && one.ok() && two.ok() && waitset.ok());
  waitset->attach(sub.value());
  ASSERT_TRUE(one->wait_for_subscribers(1, nullptr));
  ASSERT_TRUE(two->wait_for_subscribers(1, nullptr));
  EXPECT_TRUE(eventually([&] { return sub->matched() == 2; }));
  std::vector<std::array<std::uint8_t, 16>> ids;
  for (int round = 0; round < 2; ++round) {
    ASSERT_TRUE(one->publish(clock_cdr(1)).ok());
    ASSERT_TRUE(two->publish(clock_cdr(2)).ok());
  }
  std::array<std::uint8_t, 16> of_one{}, of_two{};
  for (int i = 0; i < 4; ++i) {
    Received r;
    ASSERT_TRUE(take_within(waitset.value(), sub.value(), r)) << "sample " << i;
    auto& id = r.cdr[4] == std::byte{1} ? of_one : of_two;
    if (id == std::array<std::uint8_t, 16>{}) id = r.writer;
    EXPECT_EQ(id, r.writer) << "sample " << i;
  }
  EXPECT_NE(of_one, of_two);
}

// A transient-local publisher keeps its last `depth` samples for a transient-local subscription
// created later; a volatile subscription gets only what is published after it matched.
TEST_P(SubscriptionSeam, LateTransientLocalSubscriptionGetsTheKeptSamplesVolatileDoesNot) {
  Participant p = participant();
  const std::string topic = name("clock");
  auto pub = Publisher::create(p, clock_spec(), topic, transient_keep_last(2));
  ASSERT_TRUE(pub.ok());
  for (std::uint8_t s = 1; s <= 3; ++s) ASSERT_TRUE(pub->publish(clock_cdr(s)).ok());

  auto late = Subscription::create(p, clock_spec(), topic, transient_keep_last(10));
  auto fresh = Subscription::create(p, clock_spec(), topic, volatile_keep_last(10));
  auto waitset = WaitSet::create(p);
  ASSERT_TRUE(late.ok() && fresh.ok() && waitset.ok());
  waitset->attach(late.value());
  waitset->attach(fresh.value());
  Received r;
  ASSERT_TRUE(take_within(waitset.value(), late.value(), r));
  EXPECT_TRUE(std::ranges::equal(r.cdr, clock_cdr(2)));
  ASSERT_TRUE(take_within(waitset.value(), late.value(), r));
  EXPECT_TRUE(std::ranges::equal(r.cdr, clock_cdr(3)));

  ASSERT_TRUE(pub->wait_for_subscribers(2, nullptr));
  ASSERT_TRUE(eventually([&] { return fresh->matched() == 1; }));
  ASSERT_TRUE(pub->publish(clock_cdr(4)).ok());
  ASSERT_TRUE(take_within(waitset.value(), fresh.value(), r));
  EXPECT_TRUE(std::ranges::equal(r.cdr, clock_cdr(4))) << "the volatile subscription got a kept sample";
  ASSERT_TRUE(take_within(waitset.value(), late.value(), r));
  EXPECT_TRUE(std::ranges::equal(r.cdr, clock_cdr(4)));
}

// A raw topic (outside msgs::topics()) matches by its ROS name and type.
TEST_P(SubscriptionSeam, RawTopicMatchesByRosNameAndType) {
  Participant p = participant();
  const RawTopic topic{name("events"), std::string(msgs::ParameterEvent::kType)};
  auto pub = Publisher::create(p, topic, volatile_keep_last(10));
  auto sub = Subscription::create(p, topic, volatile_keep_last(10));
  auto waitset = WaitSet::create(p);
  ASSERT_TRUE(pub.ok() && sub.ok() && waitset.ok());
  waitset->attach(sub.value());
  ASSERT_TRUE(pub->wait_for_subscribers(1, nullptr));
  msgs::ParameterEvent event;
  event.node = "/x";
  Bytes cdr;
  msgs::encode(event, cdr);
  ASSERT_TRUE(pub->publish(cdr).ok());
  Received r;
  ASSERT_TRUE(take_within(waitset.value(), sub.value(), r));
  EXPECT_TRUE(std::ranges::equal(r.cdr, cdr));
  EXPECT_EQ(sub->ros_topic(), topic.ros_name);
}

// The wait set returns when a sample arrives on any attached subscription, and after its timeout
// with none.
TEST_P(WaitSetSeam, WakesOnArrivalAndTimesOutWithNothing) {
  Participant p = participant();
  auto pub = Publisher::create(p, clock_spec(), name("a"), volatile_keep_last(10));
  auto a = Subscription::create(p, clock_spec(), name("a"), volatile_keep_last(10));
  auto b = Subscription::create(p, clock_spec(), name("b"), volatile_keep_last(10));
  auto waitset = WaitSet::create(p);
  ASSERT_TRUE(pub.ok() && a.ok() && b.ok() && waitset.ok());
  waitset->attach(a.value());
  waitset->attach(b.value());
  Result<std::int32_t> none = waitset->wait(20'000'000);
  ASSERT_TRUE(none.ok());
  EXPECT_EQ(none.value(), 0);
  ASSERT_TRUE(pub->wait_for_subscribers(1, nullptr));
  std::thread later([&] { EXPECT_TRUE(pub->publish(clock_cdr(5)).ok()); });
  Received r;
  EXPECT_TRUE(take_within(waitset.value(), a.value(), r));
  later.join();
  EXPECT_FALSE(b->take(r));
  Result<std::int32_t> after = waitset->wait(0);
  ASSERT_TRUE(after.ok());
  EXPECT_EQ(after.value(), 0);
}

// wait_for_subscribers gives up when its stop predicate says so.
bool always_stop() {
  return true;
}
TEST_P(PublisherSeam, WaitForSubscribersEndsOnStop) {
  Participant p = participant();
  auto pub = Publisher::create(p, clock_spec(), name("nobody"), volatile_keep_last(10));
  ASSERT_TRUE(pub.ok());
  EXPECT_FALSE(pub->wait_for_subscribers(1, &always_stop));
  EXPECT_EQ(pub->matched(), 0);
}

INSTANTIATE_TEST_SUITE_P(Seam, PublisherSeam, ::testing::Values("memory", "dds"), backend_name);
INSTANTIATE_TEST_SUITE_P(Seam, SubscriptionSeam, ::testing::Values("memory", "dds"), backend_name);
INSTANTIATE_TEST_SUITE_P(Seam, WaitSetSeam, ::testing::Values("memory", "dds"), backend_name);

}  // namespace
}  // namespace rbsim::node::test
