// rbsim replay: a recording republished over DDS.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "rbsim/middleware.hpp"

namespace rbsim::bag {

// The replay: an MCAP recording (rbsim run --record or rbsim record) republished over DDS with
// its recorded timing. Every channel whose schema names one of our types (msgs::topics()) and
// whose messages are CDR gets a publisher with that topic's QoS; messages go out in log-time
// order, paced by their log-time differences divided by `rate`, steered by rosbag2's player
// services (PlayOptions::services).

struct PlayOptions {
  std::string path;
  double rate = 1.0;  // real-time factor on log time; 0: as fast as possible
  std::vector<std::string>
      topics;  // recorded names ("/rbsim/body_states") or suffixes ("body_states"); empty: all
  double start_offset =
      0.0;             // seconds of log time skipped at the start (the scene description is still sent)
  bool clock = false;  // publish rosgraph_msgs/Clock on /clock with each message's log time
                       // (recorded /clock messages are then not replayed)
  std::optional<std::string> ns;  // republish under /<ns>/<name> instead of the recorded names
  std::int32_t keep_last = 0;     // per-step writers keep last N instead of keep all (0)
  // The player (rosbag2's controls): services on <node>/pause, resume, toggle_paused, is_paused,
  // get_rate, set_rate, seek, play_next, burst (rosbag2_interfaces/srv/...), for the participant's
  // node name (rbsim replay: /rbsim_player).
  bool services = true;
  bool start_paused = false;                // only the latched topics go out until resumed
  std::optional<double> playback_duration;  // s of log time from the start (offset) to play, then end
  std::optional<double> playback_until;     // simulated time (s) past which a pass ends
  double delay = 0.0;                       // s to wait before the first message of the first pass
  double service_wait_s = 10.0;             // how long seek, play_next and burst wait for the loop
};

// Where the player stands (Player::status(), from any thread).
struct PlayerStatus {
  std::uint64_t log_time = 0;             // the player's clock, log time (ns)
  std::optional<std::uint64_t> sim_time;  // the simulated time of the last message published (ns)
  double rate = 1.0;                      // 0: as fast as possible
  bool paused = false;
};

class Player {
 public:
  // Opens the recording and creates the publishers. Errors: unreadable or non-MCAP input, no rbsim
  // topics in the log, --topics names the log does not have.
  static Result<std::unique_ptr<Player>> open(const node::Participant& participant,
                                              const PlayOptions& options);
  ~Player();

  struct Output {
    std::string
        recorded;       // channel topic in the log ("/rbsim/body_states"), empty for the synthesized /clock
    std::string topic;  // topic published
    std::uint64_t messages = 0;  // messages of the channel in the log (0 when unknown)
    std::string type;            // "rbsim_msgs/msg/BodyStates" (the recorded schema's name)
    std::string schema;          // the recorded ros2msg schema text (this build's for the synthesized /clock)
    bool latched = false;        // transient local (the scene description)
  };
  const std::vector<Output>& outputs() const { return outputs_; }
  std::uint64_t first_log_time() const { return first_log_time_; }
  std::uint64_t last_log_time() const { return last_log_time_; }

  // Waits until `count` subscriptions match the body-state publisher (or, without body states,
  // the first one); false when `stop` turned true.
  bool wait_for_subscribers(std::int32_t count, bool (*stop)());
  // A second consumer of what is published (rbsim replay --foxglove): `message` gets every message
  // as it is published, with the index of its output (outputs()) and its simulated time (the
  // message's own stamp; the log time for messages without one), `pass` is called at the start of
  // every play() and after every seek (a new session: the timeline jumped), before the latched
  // messages, with the simulated time playing starts at (the first per-step message it will play;
  // nullopt: none left), so a viewer knows where a paused replay stands. Called on the thread that
  // plays; must not block.
  struct Tap {
    std::function<void(std::optional<std::uint64_t> start_sim_time_ns)> pass;
    std::function<void(std::size_t output, std::uint64_t sim_time_ns, std::span<const std::byte> cdr)>
        message;
  };
  // Plays the log once from the start offset (latched topics first, then the rest paced by the
  // player's clock; the player's requests carried out on the way: a seek re-sends the latched
  // topics as of the place it lands and makes /clock jump there); Ok(false) when `stop` turned true
  // on the way.
  Result<bool> play(bool (*stop)(), const Tap* tap = nullptr);
  PlayerStatus status() const;
  // The player's services as functions of a CDR request (rosbag2_interfaces types), the handlers
  // its DDS services run, for another front end (rbsim replay --foxglove); a nullopt answer: a
  // malformed request the response has no field to refuse. Valid while the replay lives.
  struct PlayerService {
    std::string name;  // "pause"
    std::string type;  // "rosbag2_interfaces/srv/Pause"
    std::function<std::optional<Bytes>(std::span<const std::byte> request)> call;
  };
  std::vector<PlayerService> player_services() const;
  // No more playing: the player's requests waiting for the loop (seek, play_next, burst) are
  // answered at once and new ones refused, so a front end serving them can stop without waiting.
  void close_player();
  // Waits (bounded) until the subscribers acknowledged everything published, so nothing in
  // flight is lost when the replay exits.
  [[nodiscard]] Status finish(double timeout_s = 30.0);
  std::uint64_t published() const { return published_; }
  // Channels left out (not CDR, or a definition that differs from this build's).
  const std::vector<std::string>& warnings() const { return warnings_; }

 private:
  Player() = default;
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::vector<Output> outputs_;
  std::vector<std::string> warnings_;
  std::uint64_t first_log_time_ = 0, last_log_time_ = 0;
  std::uint64_t published_ = 0;
};

}  // namespace rbsim::bag
