// rbsim replay: republish a recording over DDS with its recorded timing.
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <memory>
#include <mutex>
#include <thread>

#include "cli_util.hpp"
#include "commands.hpp"
#include "rbsim/counts.hpp"
#include "rbsim/dds.hpp"
#include "rbsim/player.hpp"
#include "rbsim/rosout.hpp"
#include "validators.hpp"

namespace rbsim::cli {

namespace {
struct ReplayArgs {
  bag::PlayOptions replay;
  std::string ns;
  std::uint32_t domain = node::kDomainFromEnvironment;  // add_domain_option sets it
  node::NodeName node{"/", "rbsim_player"};             // as rosbag2's player names its node
  bool loop = false;
  std::int32_t wait_for = 0;
  bool quiet = false;
  FoxgloveArgs foxglove;  // --foxglove [ADDR:]PORT and its access options
};

// The progress line on a terminal (stderr): the player's clock, the simulated time, the rate and
// whether it is paused, redrawn every 200 ms on a thread of its own; nothing when stderr is not a
// terminal or with --quiet. Cleared when it stops.
class ProgressLine {
 public:
  ProgressLine(const bag::Player& replay, bool on) {
    if (!on || ::isatty(STDERR_FILENO) == 0) return;
    thread_ = std::thread([this, &replay] {
      std::unique_lock lock(mutex_);
      while (!done_) {
        draw(replay);
        wake_.wait_for(lock, std::chrono::milliseconds(200));
      }
      std::fprintf(stderr, "\r\033[K");
      std::fflush(stderr);
    });
  }
  ~ProgressLine() {
    {
      const std::lock_guard lock(mutex_);
      done_ = true;
    }
    wake_.notify_one();
    if (thread_.joinable()) thread_.join();
  }

 private:
  static void draw(const bag::Player& replay) {
    const bag::PlayerStatus s = replay.status();
    const double at = static_cast<double>(s.log_time - std::min(s.log_time, replay.first_log_time())) * 1e-9;
    const double span = static_cast<double>(replay.last_log_time() - replay.first_log_time()) * 1e-9;
    char sim[48] = "-";
    if (s.sim_time) std::snprintf(sim, sizeof sim, "%.3f s", static_cast<double>(*s.sim_time) * 1e-9);
    char rate[32] = "as fast as possible";
    if (s.rate > 0) std::snprintf(rate, sizeof rate, "%gx", s.rate);
    std::fprintf(stderr, "\r\033[K[%s] log %.3f / %.3f s, simulated %s, rate %s",
                 s.paused ? "paused" : "playing", at, span, sim, rate);
    std::fflush(stderr);
  }
  std::mutex mutex_;
  std::condition_variable wake_;
  bool done_ = false;
  std::thread thread_;
};

// The player's services for Foxglove's Service Call panel, <node>/pause ... burst (cdr, or json the
// server converts by their schemas): the same handlers as the player's DDS services. A request too
// malformed to answer fails the call.
std::vector<foxglove::HostedService> player_services(const bag::Player& replay, const std::string& node) {
  std::vector<foxglove::HostedService> hosted;
  for (bag::Player::PlayerService& s : replay.player_services()) {
    hosted.push_back(hosted_service(
        node, s.name, s.type,
        [call = std::move(s.call), type = s.type](std::span<const std::byte> request) -> Result<Bytes> {
          std::optional<Bytes> reply = call(request);
          if (!reply) return Error{"a malformed " + type + " request", ErrorCode::InvalidArgument};
          return std::move(*reply);
        }));
  }
  return hosted;
}

// One Foxglove channel per replayed output, with the recording's own schema.
std::vector<foxglove::ChannelSpec> foxglove_channels(const bag::Player& replay) {
  std::vector<foxglove::ChannelSpec> channels;
  for (const auto& o : replay.outputs()) {
    foxglove::ChannelSpec c;
    c.topic = o.topic;
    c.schema_name = o.type;
    c.schema = o.schema;
    c.latched = o.latched;
    channels.push_back(std::move(c));
  }
  return channels;
}

// The start lines: the file, its span, the rate, then each output with its message count.
void print_start(const ReplayArgs& a, const bag::Player& replay, const node::Participant& participant) {
  const double span = static_cast<double>(replay.last_log_time() - replay.first_log_time()) * 1e-9;
  char rate[32] = "as fast as possible";
  if (a.replay.rate > 0) std::snprintf(rate, sizeof rate, "%gx", a.replay.rate);
  RBSIM_LOG(Info, "rbsim replay: %s (%s of log time) on %s, rate %s%s:\n", a.replay.path.c_str(),
            format_seconds(span).c_str(), participant.description().c_str(), rate, a.loop ? ", looping" : "");
  for (const auto& o : replay.outputs()) {
    if (o.recorded.empty()) {
      RBSIM_LOG(Info, "  %-28s (log time of each message)\n", o.topic.c_str());
    } else if (o.recorded == o.topic) {
      RBSIM_LOG(Info, "  %-28s %llu messages\n", o.topic.c_str(),
                static_cast<unsigned long long>(o.messages));
    } else {
      RBSIM_LOG(Info, "  %-28s %llu messages, as %s\n", o.recorded.c_str(),
                static_cast<unsigned long long>(o.messages), o.topic.c_str());
    }
  }
}

int replay_command(ReplayArgs a) {
  // Ctrl-C and SIGTERM only raise a flag from here on, before anything a stop must undo exists
  // (a participant, a listener, an output file): a stop at any stage of start-up ends cleanly.
  install_stop_handlers();
  if (!a.ns.empty()) a.replay.ns = a.ns;
  auto participant = node::create_dds_participant(a.domain, a.node);
  if (!participant) return fail("replay", participant.error().message);
  auto rosout = node::Rosout::create(participant.value());
  if (!rosout) return fail("replay", rosout.error().message);
  auto opened = bag::Player::open(participant.value(), a.replay);
  if (!opened) return fail("replay", opened.error().message);
  bag::Player& replay = *opened.value();
  for (const std::string& w : replay.warnings()) RBSIM_LOG(Warn, "rbsim replay: warning: %s\n", w.c_str());
  // --foxglove: one channel per replayed output with the recording's own schema; the replay's
  // pacing is the one clock, the server is fed from the tap as each message goes out over DDS.
  std::unique_ptr<foxglove::Server> server;
  // Before the server goes (its service thread may be serving a seek that waits for the loop),
  // the player is closed: that seek is answered at once.
  struct ClosePlayer {
    bag::Player& replay;
    ~ClosePlayer() { replay.close_player(); }
  } close_player{replay};
  bag::Player::Tap tap;
  std::optional<std::uint64_t> last_time;  // the last time message sent (none yet this session)
  if (a.foxglove.address) {
    auto started = start_foxglove("rbsim replay", a.foxglove, foxglove_channels(replay), nullptr,
                                  participant.value().node().fully_qualified(),
                                  player_services(replay, participant.value().node().fully_qualified()));
    if (!started) return fail("replay", started.error().message, foxglove_exit_status(started.error()));
    server = std::move(started.value());
    foxglove::Server* srv = server.get();
    // A session starts with the time playing starts at, before the latched messages (stamped
    // where the scene began): a viewer joining the replay while it is paused there gets that time
    // first (Server::time), not a clock of 0 that the first step would jump away from.
    tap.pass = [srv, &last_time](std::optional<std::uint64_t> at) {
      srv->new_session();
      last_time = at;
      if (at) srv->time(*at);
    };
    tap.message = [srv, &last_time](std::size_t output, std::uint64_t t, std::span<const std::byte> cdr) {
      if (!last_time || t > *last_time) {
        srv->time(t);
        last_time = t;
      }
      srv->publish(static_cast<foxglove::ChannelId>(output + 1), t, cdr);
    };
  }
  if (!a.quiet) print_start(a, replay, participant.value());
  if (a.wait_for > 0) {
    if (!a.quiet) RBSIM_LOG(Info, "rbsim replay: waiting for %d subscriber(s)...\n", a.wait_for);
    if (!replay.wait_for_subscribers(a.wait_for, stop_requested)) {
      if (!a.quiet) RBSIM_LOG(Info, "rbsim replay: stopped while waiting, nothing published\n");
      return 0;
    }
  }
  std::uint64_t passes = 0;
  bool complete = true;
  std::optional<ProgressLine> progress;
  progress.emplace(replay, !a.quiet);
  do {
    auto played = replay.play(stop_requested, server ? &tap : nullptr);
    if (!played) return fail("replay", played.error().message);
    complete = played.value();
    if (complete) ++passes;
  } while (a.loop && complete && !stop_requested());
  progress.reset();
  if (complete) {
    if (Status st = replay.finish(); !st) return fail("replay", st.error().message);
  }
  if (server) (void)server->flush(2.0);  // viewers that keep up get the end of the log
  if (!a.quiet) {
    RBSIM_LOG(Info, "rbsim replay: %s after %llu complete pass%s, %llu messages published%s\n",
              complete ? "done" : "stopped", static_cast<unsigned long long>(passes),
              plural(passes, "", "es"), static_cast<unsigned long long>(replay.published()),
              server ? ("; " + foxglove_summary(*server)).c_str() : "");
  }
  return 0;
}
}  // namespace

Subcommand add_replay_command(CLI::App& parent) {
  auto a = std::make_shared<ReplayArgs>();
  CLI::App* app =
      parent.add_subcommand("replay", "Republish a recording (MCAP) over DDS with its recorded timing");
  app->add_option("in", a->replay.path, "MCAP recording (rbsim run --record or rbsim record)")->required();
  app->add_option("--rate", a->replay.rate,
                  "Real-time factor on the recorded log times (2 = twice as fast; 0 = as fast as possible)")
      ->check(non_negative())
      ->default_str("1");
  app->add_flag("--loop", a->loop, "Start again at the end, until Ctrl-C");
  app->add_option("--topics", a->replay.topics,
                  "Topics to replay, comma-separated or repeated (recorded names like /rbsim/body_states, or "
                  "body_states); default all")
      ->delimiter(',')
      ->allow_extra_args(false);
  app->add_option(
         "--start-offset", a->replay.start_offset,
         "Skip this many seconds of log time at the start (the scene description is still published first)")
      ->check(non_negative());
  app->add_flag(
      "--clock", a->replay.clock,
      "Publish rosgraph_msgs/Clock on /clock carrying the log time of each message replayed (recorded "
      "/clock messages are then left out)");
  add_domain_option(app, a->domain);
  add_node_name_option(app, a->node);
  app->add_option("--namespace", a->ns, "Republish under /<namespace>/<name> instead of the recorded names")
      ->check(ros_namespace());
  app->add_option("--wait-for-subscribers", a->wait_for,
                  "Wait until N subscribers match the body states first")
      ->check(non_negative());
  app->add_option(
         "--keep-last", a->replay.keep_last,
         "Per-step writers keep the last N samples instead of all (the replay never waits for a slow "
         "subscriber, which may then lose samples)")
      ->check(positive());
  app->add_flag("--start-paused", a->replay.start_paused,
                "Start paused: only the latched topics (scene description, markers) go out until "
                "/rbsim_player/resume (or toggle_paused, play_next, burst)");
  app->add_option(
         "--playback-duration", a->replay.playback_duration,
         "Play this many seconds of log time from the start (after --start-offset), then end the pass")
      ->check(non_negative());
  app->add_option(
         "--playback-until", a->replay.playback_until,
         "End each pass past this simulated time (s; the time the messages carry, as seek takes it); "
         "with --playback-duration, past both")
      ->check(non_negative());
  app->add_option("--delay", a->replay.delay,
                  "Wait this many seconds before publishing (after --wait-for-subscribers)")
      ->check(non_negative());
  add_foxglove_option(app, a->foxglove);
  app->add_flag("-q,--quiet", a->quiet, "Only errors (and --foxglove's listening line)");
  app->footer(
      "Every channel whose schema is an rbsim type (rbsim_msgs/SceneDescription, BodyStates, SpringStates, "
      "EnergyTerms, geometry_msgs/PoseArray, visualization_msgs/MarkerArray, rosgraph_msgs/Clock) is "
      "republished byte for byte with the node's QoS (the scene description transient local), in log-time "
      "order. "
      "Ctrl-C stops cleanly. --foxglove also serves them to Foxglove with the recording's schemas (log time "
      "= "
      "the messages' simulated time; a new session on every --loop pass), with the player services below "
      "for its Service Call panel (cdr).\n"
      "Player services (rosbag2_interfaces/srv, as ros2 bag play offers them) under the node name "
      "(--node-name, default /rbsim_player): pause, resume, toggle_paused, is_paused, get_rate, set_rate "
      "(> 0 only), seek (simulated time; the latched topics are sent again and /clock jumps), play_next and "
      "burst (while paused). On a terminal a progress line shows the clock, rate and whether it is "
      "paused.\n"
      "Exit status: 0 done or stopped by Ctrl-C/SIGTERM, 1 error (unreadable recording, no rbsim topics, DDS "
      "failure), 2 usage error.");
  return {app, [a] { return replay_command(*a); }};
}

}  // namespace rbsim::cli
