// The node's DDS sink at library level: the options it refuses.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <string>

#include "rbsim/dds.hpp"
#include "rbsim/dds_sink.hpp"

namespace rbsim::node {
namespace {

// Publishing every 0th (or -2nd) step is an error from create(), not a silent every 1.
TEST(DdsSink, PublishEveryBelowOneIsRefusedAtCreate) {
  Result<Participant> participant = create_dds_participant(143);
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
// boundary of the step it is for (Pacer::wait, DriverOptions::pace). Each due time is checked
// against clock readings taken just before and just after the begin() or rebase() it counts from,
// and each wait against the due time it reports, so a loaded machine (a thread descheduled at any
// point) cannot make the test fail.
std::int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

TEST(Pacer, RebaseAndSetPaceCountTheNextStepFromNow) {
  WorldDef def;
  def.bodies.push_back(BodyDef{{{-1.0, 0.0}, {1.0, 0.0}}, {1.0, 1.0}});
  def.dt = 0.01;
  Result<World> world = World::create(def);
  ASSERT_TRUE(world.ok());
  World& w = world.value();
  Pacer pacer(1.0, 1);
  // The step after `step` is due `after_ns` past a moment in [before, after]; wait() returns no
  // earlier than that.
  const auto expect_due = [&](std::int64_t step, std::int64_t before, std::int64_t after,
                              std::int64_t after_ns) {
    w.set_step_index(step);
    const std::optional<std::int64_t> due = pacer.due_ns(w);
    ASSERT_TRUE(due.has_value()) << "step " << step;
    EXPECT_GE(*due, before + after_ns) << "step " << step;
    EXPECT_LE(*due, after + after_ns) << "step " << step;
    pacer.wait(w);
    EXPECT_GE(now_ns(), *due) << "step " << step;
  };
  std::int64_t before = now_ns();
  ASSERT_TRUE(pacer.begin(Scene{}, w).ok());
  std::int64_t after = now_ns();
  // From begin() at step 0: step 1 is due dt later.
  expect_due(0, before, after, 10'000'000);
  // A reset: from step 100 (never reached in wall time) back to 0; step 1 goes at once, step 2
  // dt after it.
  w.set_step_index(100);
  pacer.rebase(w);
  w.set_step_index(0);
  before = now_ns();
  pacer.rebase(w);
  after = now_ns();
  expect_due(0, before, after, 0);
  expect_due(1, before, after, 10'000'000);
  // Half the rate: two dt per step, counted from the rebase at step 40 (not from begin(), from
  // which step 42 would be due 0.84 s later).
  pacer.set_pace(0.5, 1);
  w.set_step_index(40);
  before = now_ns();
  pacer.rebase(w);
  after = now_ns();
  expect_due(40, before, after, 0);
  expect_due(41, before, after, 20'000'000);
  // Not paced: as fast as possible, and a step that is not published.
  pacer.set_pace(0.0, 1);
  EXPECT_FALSE(pacer.due_ns(w).has_value());
  pacer.set_pace(1.0, 4);
  w.set_step_index(5);  // step 6 is not a multiple of 4
  EXPECT_FALSE(pacer.due_ns(w).has_value());
}

}  // namespace
}  // namespace rbsim::node
