// Subscription::take at library level: samples are borrowed from DDS, not copied.
#include <gtest/gtest.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <cstddef>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "rbsim/dds.hpp"

namespace rbsim::node {
namespace {

// A rosgraph_msgs/Clock in CDR: the encapsulation header (little-endian CDR), sec, nanosec.
std::vector<std::byte> clock_cdr(std::uint8_t sec) {
  return {std::byte{0}, std::byte{1}, std::byte{0}, std::byte{0}, std::byte{sec}, std::byte{0},
          std::byte{0}, std::byte{0}, std::byte{0}, std::byte{0}, std::byte{0},   std::byte{0}};
}

// Takes one sample within a bounded time (200 tries, 10 ms apart).
bool take_within(Subscription& sub, Received& out) {
  for (int i = 0; i < 200; ++i) {
    if (sub.take(out)) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return false;
}

// A taken sample keeps its bytes while its Received holds them: through a move and while later
// samples are taken into other Receiveds.
TEST(Subscription, TakenBytesStayValidWhileTheReceivedHoldsThem) {
  Result<Participant> participant = create_dds_participant(144);
  ASSERT_TRUE(participant.ok()) << participant.error().message;
  const msgs::TopicSpec& spec = msgs::topic(msgs::TopicId::Clock);
  // A topic of this process alone: tests of other processes may share the domain.
  const std::string name = "/subscription_test_" + std::to_string(::getpid()) + "/clock";
  const QosSpec qos = qos_for(spec, 10);
  Result<Subscription> sub = Subscription::create(participant.value(), spec, name, qos);
  ASSERT_TRUE(sub.ok()) << sub.error().message;
  Result<Publisher> pub = Publisher::create(participant.value(), spec, name, qos);
  ASSERT_TRUE(pub.ok()) << pub.error().message;
  for (int i = 0; i < 200 && pub.value().matched() < 1; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ASSERT_EQ(pub.value().matched(), 1);

  const std::array<std::vector<std::byte>, 3> sent{clock_cdr(7), clock_cdr(8), clock_cdr(9)};
  for (const auto& s : sent) ASSERT_TRUE(pub.value().publish(s).ok());
  Received first;
  ASSERT_TRUE(take_within(sub.value(), first));
  Received moved = std::move(first);
  Received second, third;
  ASSERT_TRUE(take_within(sub.value(), second));
  ASSERT_TRUE(take_within(sub.value(), third));
  const std::array<const Received*, 3> got{&moved, &second, &third};
  for (std::size_t i = 0; i < sent.size(); ++i) {
    EXPECT_EQ(std::vector<std::byte>(got[i]->cdr.begin(), got[i]->cdr.end()), sent[i]) << "sample " << i;
    EXPECT_TRUE(got[i]->held) << "sample " << i;
  }
  // Taking into a Received that holds a sample replaces it.
  ASSERT_TRUE(pub.value().publish(clock_cdr(10)).ok());
  ASSERT_TRUE(take_within(sub.value(), second));
  EXPECT_EQ(std::vector<std::byte>(second.cdr.begin(), second.cdr.end()), clock_cdr(10));
  EXPECT_EQ(std::vector<std::byte>(moved.cdr.begin(), moved.cdr.end()), sent[0]);
}

// The one wait for subscribers (node's and replay's --wait-for-subscribers): it returns once
// `count` match, and gives up when its stop flag turns true, looking at it between polls.
int g_stop_calls = 0;
int g_stop_after = 0;
bool stop_after_some_calls() {
  return ++g_stop_calls > g_stop_after;
}

TEST(Publisher, WaitForSubscribersUntilMatchedOrStopped) {
  Result<Participant> participant = create_dds_participant(144);
  ASSERT_TRUE(participant.ok()) << participant.error().message;
  const msgs::TopicSpec& spec = msgs::topic(msgs::TopicId::Clock);
  const std::string name = "/subscription_test_wait_" + std::to_string(::getpid()) + "/clock";
  const QosSpec qos = qos_for(spec, 10);
  Result<Publisher> pub = Publisher::create(participant.value(), spec, name, qos);
  ASSERT_TRUE(pub.ok()) << pub.error().message;
  EXPECT_TRUE(pub.value().wait_for_subscribers(0, nullptr));  // none asked for: at once

  g_stop_calls = 0;
  g_stop_after = 3;
  EXPECT_FALSE(pub.value().wait_for_subscribers(1, stop_after_some_calls));  // nobody subscribes
  EXPECT_EQ(g_stop_calls, 4);

  Result<Subscription> sub = Subscription::create(participant.value(), spec, name, qos);
  ASSERT_TRUE(sub.ok()) << sub.error().message;
  g_stop_calls = 0;
  g_stop_after = 500;  // 10 s of 20 ms polls
  EXPECT_TRUE(pub.value().wait_for_subscribers(1, stop_after_some_calls));
  EXPECT_GE(pub.value().matched(), 1);
}

}  // namespace
}  // namespace rbsim::node
