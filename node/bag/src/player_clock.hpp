// The replay's player state, shared by the replay loop and the player's services
// (rosbag2_interfaces on <node>/pause, resume, ...): paused or playing, the rate, the one pacing
// clock of the replay (log time against monotonic wall time), and the requests only the loop can
// carry out (seek, play_next/burst), each answered once the loop did it. Every wait is bounded.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "rbsim/player.hpp"
#include "rbsim/service.hpp"

namespace rbsim::node {
class ServiceSet;
}  // namespace rbsim::node

namespace rbsim::bag {

class PlayerClock {
 public:
  PlayerClock(double rate, bool paused) : rate_(rate), paused_(paused) {}

  // --- the services' side (any thread) ---
  void pause();
  void resume();
  bool toggle_paused();  // returns whether it is paused now
  bool paused() const;
  double rate() const;         // 0: as fast as possible
  bool set_rate(double rate);  // only > 0 (as rosbag2's)
  // Asks the loop to seek to simulated time `sim_ns`; waits (up to `timeout_s`) for its answer.
  bool seek(std::uint64_t sim_ns, double timeout_s);
  // Only while paused: asks the loop to publish `count` messages (0: the rest of the pass) at once,
  // waits (up to `timeout_s`) until it did or the pass ended; returns how many it published.
  std::uint64_t burst(std::uint64_t count, double timeout_s);
  PlayerStatus status() const;

  // --- the loop's side (the thread that plays) ---
  enum class Next { Publish, Seek, Stop };
  // Waits until the message at `log_time` is due: playing, at its paced wall time (at once at rate
  // 0); paused, when a play_next/burst asks for it. Seek when a seek request came first, Stop when
  // `stop` turned true; polls `stop` at least every 50 ms.
  Next wait_due(std::uint64_t log_time, bool (*stop)());
  // After publishing the message wait_due() let through: counts it for a burst (and moves the
  // clock to it: a stepped message is due at once).
  void published(std::uint64_t log_time, std::optional<std::uint64_t> sim_ns);
  // The pending seek target, taken (the answer goes through seek_done()).
  std::optional<std::uint64_t> take_seek();
  // Answers the seek taken; when it moved, the clock jumps to `log_time`.
  void seek_done(bool moved, std::uint64_t log_time);
  // Starts the clock at `log_time` (a pass's first message, the place a seek landed).
  void jump(std::uint64_t log_time);
  // The pass ended (or the replay stopped): a burst waiting gets what was published, a seek false.
  void pass_end();
  // No loop will play any more (the replay is going): waiting requests are answered at once, new
  // ones refused.
  void close();

 private:
  std::int64_t due_wall_locked(std::uint64_t log_time) const;
  // The control's invariants (asserted where the loop acts on it; mutex_ held).
  void check_locked() const;
  std::uint64_t now_log_locked() const;
  mutable std::mutex mutex_;
  std::condition_variable loop_wake_, answer_;
  double rate_;
  bool paused_;
  std::int64_t anchor_wall_ = 0;  // monotonic ns
  std::uint64_t anchor_log_ = 0;  // the log time at anchor_wall_ (the frozen clock while paused)
  std::optional<std::uint64_t> sim_ns_;
  // seek: the request, and its answer
  std::optional<std::uint64_t> seek_request_;
  std::uint64_t seek_serial_ = 0, seek_answered_ = 0;
  bool seek_answer_ = false;
  // burst: messages still wanted, published so far, and whether it is over
  std::uint64_t burst_left_ = 0, burst_done_ = 0;
  bool burst_active_ = false;
  bool closed_ = false;
};

// One of the player's services: its name under the node, its type and its handler on CDR.
struct PlayerService {
  std::string name;  // "pause"
  std::string type;  // "rosbag2_interfaces/srv/Pause"
  node::ServiceServer::Handler handler;
};
// The player's services, as rosbag2's player offers them (rosbag2_interfaces): pause, resume,
// toggle_paused, is_paused, get_rate, set_rate, seek, play_next, burst. Seek, play_next and burst
// wait up to `wait_s` for the loop. Served over DDS (add_player_services) and, through
// Player::player_services(), by the Foxglove server.
std::vector<PlayerService> player_services(PlayerClock& control, double wait_s);

// The player's services on `set` (rosbag2_interfaces, as rosbag2's player offers them):
// <node>/pause, resume, toggle_paused, is_paused, get_rate, set_rate, seek, play_next, burst.
// Seek, play_next and burst wait up to `wait_s` for the loop.
[[nodiscard]] Status add_player_services(node::ServiceSet& set, const node::Participant& participant,
                                         const std::string& node_name, PlayerClock& control, double wait_s);

}  // namespace rbsim::bag
