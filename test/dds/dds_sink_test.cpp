// The node's DDS sink at library level: the options it refuses.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>

#include "rbsim/dds_sink.hpp"

namespace rbsim::node {
namespace {

// Publishing every 0th (or -2nd) step is an error from create(), not a silent every 1.
TEST(DdsSink, PublishEveryBelowOneIsRefusedAtCreate) {
  Result<Participant> participant = Participant::create(143);
  ASSERT_TRUE(participant.ok()) << participant.error().message;
  for (const std::int64_t every : {std::int64_t{0}, std::int64_t{-2}}) {
    NodeOptions options;
    options.publish_every = every;
    auto sink = DdsSink::create(participant.value(), options);
    ASSERT_FALSE(sink.ok()) << "publish_every " << every;
    EXPECT_NE(sink.error().message.find("at least 1"), std::string::npos) << sink.error().message;
  }
  NodeOptions options;  // publish_every 1 is accepted
  auto sink = DdsSink::create(participant.value(), options);
  EXPECT_TRUE(sink.ok()) << sink.error().message;
}

}  // namespace
}  // namespace rbsim::node
