// The replay's player state (node/bag/src/player.hpp) without DDS: the pacing clock under pause, resume
// and rate changes; rates <= 0 refused; play_next/burst only while paused, counted as the loop
// publishes; a seek answered by the loop, withdrawn when no loop takes it, refused once closed.
#include <gtest/gtest.h>

#include <chrono>
#include <future>
#include <limits>
#include <thread>

#include "player_clock.hpp"

namespace rbsim::bag {

using namespace node;
namespace {

bool never() {
  return false;
}
bool always() {
  return true;
}

constexpr std::uint64_t kMs = 1'000'000;

TEST(PlayerClock, PacesAtItsRateAndHoldsWhilePaused) {
  PlayerClock c(2.0, false);
  c.jump(10 * kMs);
  const auto t0 = std::chrono::steady_clock::now();
  // 200 ms of log at 2x: due 100 ms after the jump.
  EXPECT_EQ(c.wait_due(210 * kMs, never), PlayerClock::Next::Publish);
  const double waited = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_GE(waited, 0.095);
  EXPECT_LT(waited, 0.5);
  c.pause();
  const std::uint64_t frozen = c.status().log_time;
  EXPECT_TRUE(c.status().paused);
  std::this_thread::sleep_for(std::chrono::milliseconds(60));
  EXPECT_EQ(c.status().log_time, frozen);  // the clock stands while paused
  // A paused loop waits for a request; stop ends the wait.
  auto stopped = std::async(std::launch::async, [&] { return c.wait_due(frozen, always); });
  EXPECT_EQ(stopped.get(), PlayerClock::Next::Stop);
  c.resume();
  EXPECT_FALSE(c.status().paused);
  EXPECT_GE(c.status().log_time, frozen);
}

TEST(PlayerClock, RefusesRatesNotAboveZero) {
  PlayerClock c(1.0, false);
  EXPECT_FALSE(c.set_rate(0.0));
  EXPECT_FALSE(c.set_rate(-1.0));
  EXPECT_FALSE(c.set_rate(std::numeric_limits<double>::quiet_NaN()));
  EXPECT_FALSE(c.set_rate(std::numeric_limits<double>::infinity()));
  EXPECT_EQ(c.rate(), 1.0);
  EXPECT_TRUE(c.set_rate(0.25));
  EXPECT_EQ(c.rate(), 0.25);
  EXPECT_TRUE(c.toggle_paused());
  EXPECT_FALSE(c.toggle_paused());
}

TEST(PlayerClock, BurstOnlyWhilePausedCountsWhatTheLoopPublishes) {
  PlayerClock c(1.0, false);
  EXPECT_EQ(c.burst(3, 1.0), 0u);  // playing: refused at once
  c.pause();
  c.jump(0);
  std::thread loop([&] {
    for (std::uint64_t t = 1; t <= 3; ++t) {
      ASSERT_EQ(c.wait_due(t * 1000 * kMs, never),
                PlayerClock::Next::Publish);  // far in the future: only a burst
      c.published(t * 1000 * kMs, t);
    }
  });
  EXPECT_EQ(c.burst(3, 5.0), 3u);
  loop.join();
  EXPECT_EQ(c.status().log_time, 3000 * kMs);  // the paused clock stands at the last stepped message
  EXPECT_EQ(c.status().sim_time, 3u);
  // A burst longer than the pass: what was published when the pass ended.
  std::thread short_pass([&] {
    ASSERT_EQ(c.wait_due(4000 * kMs, never), PlayerClock::Next::Publish);
    c.published(4000 * kMs, std::nullopt);
    c.pass_end();
  });
  EXPECT_EQ(c.burst(0, 5.0), 1u);
  short_pass.join();
}

TEST(PlayerClock, SeekIsAnsweredByTheLoopWithdrawnWithoutOneRefusedOnceClosed) {
  PlayerClock c(1.0, true);
  std::thread loop([&] {
    ASSERT_EQ(c.wait_due(0, never), PlayerClock::Next::Seek);
    ASSERT_EQ(c.take_seek(), std::optional<std::uint64_t>(1'500 * kMs));
    c.seek_done(true, 42 * kMs);
  });
  EXPECT_TRUE(c.seek(1'500 * kMs, 5.0));
  loop.join();
  EXPECT_EQ(c.status().log_time, 42 * kMs);  // the clock jumped where the seek landed
  EXPECT_FALSE(c.seek(1, 0.1));              // no loop: withdrawn after the wait
  EXPECT_FALSE(c.take_seek().has_value());
  c.close();
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_FALSE(c.seek(1, 5.0));
  EXPECT_EQ(c.burst(1, 5.0), 0u);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 1.0);
}

}  // namespace
}  // namespace rbsim::bag
