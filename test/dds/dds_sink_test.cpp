// The node's DDS sink at library level: the options it refuses.
#include <gtest/gtest.h>

#include <chrono>
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

// The pacer after a pause or a reset (Sink::rebase) and a change of pace (set_pace): the step
// after the rebase goes out at once, the next one dt / rate after it, not at the time the original
// start implies (a burst to catch up, or a long wait after a reset). The wait comes before the
// boundary of the step it is for (Pacer::wait, DriverOptions::pace).
TEST(Pacer, RebaseAndSetPaceCountTheNextStepFromNow) {
  WorldDef def;
  def.bodies.push_back(BodyDef{{{-1.0, 0.0}, {1.0, 0.0}}, {1.0, 1.0}});
  def.dt = 0.01;
  Result<World> world = World::create(def);
  ASSERT_TRUE(world.ok());
  World& w = world.value();
  Pacer pacer(1.0, 1);
  ASSERT_TRUE(pacer.begin(Scene{}, w).ok());
  const auto timed_wait = [&](std::int64_t step) {  // before the boundary of step + 1
    w.set_step_index(step);
    const auto start = std::chrono::steady_clock::now();
    pacer.wait(w);
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  // From begin() at step 0: step 1 is due dt later.
  EXPECT_GE(timed_wait(0), 0.009);
  // A reset: from step 100 (never reached in wall time) back to 0; step 1 goes at once, step 2
  // dt after it.
  w.set_step_index(100);
  pacer.rebase(w);
  w.set_step_index(0);
  pacer.rebase(w);
  EXPECT_LT(timed_wait(0), 0.005);
  const double after_reset = timed_wait(1);
  EXPECT_GE(after_reset, 0.009);
  EXPECT_LT(after_reset, 0.5);
  // Half the rate: two dt per step, counted from the rebase at step 40 (not from begin()).
  pacer.set_pace(0.5, 1);
  w.set_step_index(40);
  pacer.rebase(w);
  EXPECT_LT(timed_wait(40), 0.005);
  const double slower = timed_wait(41);
  EXPECT_GE(slower, 0.019);
  EXPECT_LT(slower, 0.5);  // from begin() at step 0, step 42 would be due 0.84 s later
}

}  // namespace
}  // namespace rbsim::node
