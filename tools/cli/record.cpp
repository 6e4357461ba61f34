// rbsim record: DDS topics to MCAP until Ctrl-C, --wall-duration or --max-messages.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <memory>

#include "cli_util.hpp"
#include "commands.hpp"
#include "rbsim/bag.hpp"
#include "rbsim/dds.hpp"
#include "rbsim/mcap_sink.hpp"
#include "rbsim/node_services.hpp"
#include "rbsim/outputs.hpp"
#include "rbsim/recorder.hpp"
#include "rbsim/rosout.hpp"
#include "rbsim/service_event.hpp"
#include "rbsim/time.hpp"
#include "validators.hpp"

namespace rbsim::cli {

namespace {
constexpr int kLiveZstdLevel = -5;

struct RecordArgs {
  bag::RecorderOptions rec;
  std::uint32_t domain = node::kDomainFromEnvironment;  // add_domain_option sets it
  std::optional<double> duration;
  std::optional<double> max_file_duration;  // seconds
  std::optional<double> snapshot_duration;  // seconds
  std::string compression = "zstd";
  std::optional<int> compression_level;
  bool quiet = false;
  bool overwrite = false;
  std::optional<double> wrong_duration;
  node::NodeName node{"/", "rbsim_recorder"};  // as rosbag2's recorder names its node
  std::vector<std::string> services;           // --services
  bool all_services = false;                   // --all-services
};

// --services and --all-services as topics: each service's <service>/_service_event with its
// _Event type, the service looked up among the node's (a name under the node, "pause", or in full,
// "/rbsim/pause"). Empty when neither was given; an unknown name is a usage error naming them.
Result<std::vector<node::RawTopic>> service_event_topics(const RecordArgs& a) {
  std::vector<node::RawTopic> out;
  if (a.services.empty() && !a.all_services) return out;
  const std::string node = "/" + (a.rec.ns.starts_with('/') ? a.rec.ns.substr(1) : a.rec.ns);
  const std::vector<node::NodeServices::Served> served = node::NodeServices::catalogue();
  const auto add = [&](const node::NodeServices::Served& s) {
    out.push_back({node + "/" + s.name + std::string(msgs::kServiceEventTopicSuffix),
                   msgs::service_event_type(s.type)});
  };
  if (a.all_services) {
    for (const node::NodeServices::Served& s : served) add(s);
    return out;
  }
  for (const std::string& name : a.services) {
    const auto it = std::find_if(served.begin(), served.end(), [&](const node::NodeServices::Served& s) {
      return name == s.name || name == node + "/" + s.name;
    });
    if (it == served.end()) {
      std::string names;
      for (const node::NodeServices::Served& s : served) names += (names.empty() ? "" : ", ") + s.name;
      return Error{
          "--services: \"" + name + "\" is not a service of the node " + node + " (services: " + names + ")",
          ErrorCode::InvalidArgument};
    }
    add(*it);
  }
  return out;
}

// --max-file-duration, --snapshot-duration in ns (0 when not given), by base's one rule.
Result<std::uint64_t> duration_ns(const std::optional<double>& seconds, const char* option) {
  if (!seconds) return std::uint64_t{0};
  const Result<std::int64_t> ns = seconds_to_ns(*seconds);
  if (!ns) return Error{std::string(option) + ": " + ns.error().message};
  return static_cast<std::uint64_t>(ns.value());
}

// SIGUSR1 asks a recorder in snapshot mode for a snapshot.
std::atomic<int> g_snapshot{0};
void on_snapshot_signal(int) {
  g_snapshot.store(1, std::memory_order_relaxed);
}
void install_snapshot_handler() {
  struct sigaction sa {};
  sa.sa_handler = on_snapshot_signal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGUSR1, &sa, nullptr);
}
bool snapshot_requested() {
  return g_snapshot.exchange(0, std::memory_order_relaxed) != 0;
}

// The codec, and the outputs OUT names: one .mcap file, or a rosbag2 bag directory (`bag`)
// holding file 0; the exit status of a choice of options that cannot go together.
std::optional<int> choose_outputs(RecordArgs& a, std::string& bag, std::vector<OutputPath>& outputs) {
  // A live recorder must keep up with what arrives: zstd at a fast negative level by default, which
  // costs much less CPU than level 1 for somewhat larger files (scripts/bench-record-live measures
  // both). `rbsim run --record` writes offline and keeps level 1.
  a.rec.compression_level = a.compression_level.value_or(a.compression == "zstd" ? kLiveZstdLevel : 0);
  const Result<mcap::Compression> codec = compression_option(a.compression, a.rec.compression_level);
  if (!codec) return fail("record", codec.error().message);
  a.rec.compression = codec.value();
  // OUT ending in .mcap is one file; any other path a rosbag2 bag directory, holding file 0.
  outputs = {{a.rec.path, "OUT"}};
  const Result<std::uint64_t> file_ns = duration_ns(a.max_file_duration, "--max-file-duration");
  const Result<std::uint64_t> snapshot_ns = duration_ns(a.snapshot_duration, "--snapshot-duration");
  if (!file_ns || !snapshot_ns) return fail("record", (file_ns ? snapshot_ns : file_ns).error().message, 2);
  a.rec.max_file_duration_ns = file_ns.value();
  a.rec.snapshot_duration_ns = snapshot_ns.value();
  if (recordings::is_bag_output(a.rec.path)) {
    bag = a.rec.path;
    outputs = recordings::bag_outputs(bag, "OUT");
    a.rec.bag = bag;
  } else if (a.rec.max_file_bytes > 0 || a.rec.max_file_duration_ns > 0 || a.rec.snapshot_duration_ns > 0) {
    return fail("record",
                "--max-file-size, --max-file-duration and --snapshot-duration write a bag directory: OUT " +
                    a.rec.path + " ends in .mcap (one file); name a directory instead",
                2);
  }
  if (a.rec.snapshot_duration_ns > 0 && (a.rec.max_file_bytes > 0 || a.rec.max_file_duration_ns > 0)) {
    return fail("record", "--snapshot-duration writes one file per snapshot: it takes no --max-file-* option",
                2);
  }
  return std::nullopt;
}

// Records until a stop, --wall-duration or --max-messages; what failed, if anything did.
std::optional<std::string> record_until_stopped(const RecordArgs& a, bag::Recorder& recorder,
                                                bag::RecorderServices& services) {
  const auto start = std::chrono::steady_clock::now();
  const auto deadline = a.duration ? start + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                                 std::chrono::duration<double>(*a.duration))
                                   : std::chrono::steady_clock::time_point::max();
  std::optional<std::string> failure;
  while (!stop_requested() && std::chrono::steady_clock::now() < deadline) {
    auto polled = recorder.poll(100'000'000);  // 100 ms: Ctrl-C and --wall-duration are seen promptly
    if (!polled) {
      failure = polled.error().message;
      break;
    }
    if (a.rec.max_messages > 0 && recorder.received() >= a.rec.max_messages) break;
    if (Status st = services.carry_out(a.quiet, snapshot_requested()); !st) {
      failure = st.error().message;
      break;
    }
  }
  return failure;
}

// The end lines: per topic what arrived and what was lost, then the totals.
void print_counts(const bag::Recorder& recorder, const std::string& path) {
  std::uint64_t lost = 0, duplicates = 0;
  for (const auto& c : recorder.counts()) {
    RBSIM_LOG(Info, "  %-28s received %8llu  lost %llu%s\n", c.topic.c_str(),
              static_cast<unsigned long long>(c.received), static_cast<unsigned long long>(c.lost),
              c.duplicates > 0 ? ("  delivered twice " + std::to_string(c.duplicates)).c_str() : "");
    lost += c.lost;
    duplicates += c.duplicates;
  }
  if (duplicates > 0) {
    RBSIM_LOG(Info,
              "rbsim record: %llu samples DDS delivered again (after a reconnection) were recorded once\n",
              static_cast<unsigned long long>(duplicates));
  }
  RBSIM_LOG(Info, "rbsim record: %llu messages received, %llu lost, written to %s\n",
            static_cast<unsigned long long>(recorder.received()), static_cast<unsigned long long>(lost),
            path.c_str());
}

int record_command(RecordArgs a) {
  // Ctrl-C and SIGTERM only raise a flag from here on, before anything a stop must undo exists
  // (a participant, a listener, an output file): a stop at any stage of start-up ends cleanly.
  install_stop_handlers();
  if (a.wrong_duration) {
    RBSIM_LOG(Error,
              "rbsim record: error: --duration: a recorder runs in wall-clock time: use --wall-duration "
              "SECONDS (--duration is simulated time elsewhere)\nRun 'rbsim record --help' for usage.");
    return 2;
  }
  std::string bag;
  std::vector<OutputPath> outputs;
  if (std::optional<int> exit = choose_outputs(a, bag, outputs)) return *exit;
  Result<std::vector<node::RawTopic>> events = service_event_topics(a);
  if (!events) return fail("record", events.error().message, 2);
  a.rec.raw_topics = std::move(events.value());

  if (Status st = check_outputs(outputs, {}, a.overwrite); !st) return fail("record", st.error().message);
  std::error_code ec;
  const bool made_bag = !bag.empty() && !std::filesystem::exists(bag, ec);
  if (!bag.empty()) {
    if (Status st = recordings::make_bag_directory(bag); !st) return fail("record", st.error().message);
  }
  auto participant = node::create_dds_participant(a.domain, a.node);
  if (!participant) return fail("record", participant.error().message);
  auto rosout = node::Rosout::create(participant.value());
  if (!rosout) return fail("record", rosout.error().message);
  auto recorder = bag::Recorder::create(participant.value(), a.rec);
  if (!recorder) {
    if (made_bag) std::filesystem::remove_all(bag, ec);  // it holds at most the file just opened
    return fail("record", recorder.error().message,
                recorder.error().code == ErrorCode::InvalidArgument ? 2 : 1);
  }
  // rosbag2's recorder services on the recorder's node (/rbsim_recorder/snapshot, ...).
  auto services = bag::RecorderServices::create(participant.value(), *recorder.value());
  if (!services) return fail("record", services.error().message);
  install_snapshot_handler();
  if (!a.quiet) {
    RBSIM_LOG(Info, "rbsim record: recording %s topics under /%s on %s to %s (Ctrl-C to stop)\n",
              a.rec.topics.empty() ? "all rbsim" : "the chosen", a.rec.ns.c_str(),
              participant.value().description().c_str(), a.rec.path.c_str());
  }
  const std::optional<std::string> failure = record_until_stopped(a, *recorder.value(), *services.value());
  // Whatever stopped us, finish a valid indexed file.
  if (Status st = recorder.value()->close(); !st)
    return fail("record", st.error().message + " (the file can be repaired with rbsim log recover)");
  if (!a.quiet || failure) print_counts(*recorder.value(), a.rec.path);
  if (failure) return fail("record", *failure + " (the file was finished up to that point)");
  if (recorder.value()->received() == 0) {  // an empty file is no recording: leave nothing behind
    for (const std::string& f : recorder.value()->files()) std::remove(f.c_str());
    if (made_bag) std::filesystem::remove_all(bag, ec);
    return fail("record", "nothing received on " + participant.value().description() + " under /" + a.rec.ns +
                              "; nothing written (is a node running with the same domain and namespace?)");
  }
  return 0;
}
}  // namespace

Subcommand add_record_command(CLI::App& parent) {
  auto a = std::make_shared<RecordArgs>();
  CLI::App* app =
      parent.add_subcommand("record", "Record rbsim topics from DDS into an MCAP file (rosbag2 layout)");
  app->add_option("out", a->rec.path,
                  "Where to record: an MCAP file (a path ending in .mcap), or else a rosbag2 bag directory "
                  "(OUT/metadata.yaml and OUT/OUT_0.mcap, as ROS 2 Jazzy's recorder writes them)")
      ->required();
  app->add_option(
         "--topics", a->rec.topics,
         "Topics to record, comma-separated or repeated (body_states or /rbsim/body_states); default all")
      ->delimiter(',')
      ->allow_extra_args(false);
  app->add_option("--regex", a->rec.regex,
                  "Also record the topics whose full name matches this regular expression (ECMAScript, "
                  "the whole name: '.*states')");
  app->add_option("--exclude-topics", a->rec.exclude_topics,
                  "Topics not to record, comma-separated or repeated (wins over --topics and --regex)")
      ->delimiter(',')
      ->allow_extra_args(false);
  app->add_option("--exclude-regex", a->rec.exclude_regex,
                  "Do not record the topics whose full name matches this regular expression");
  app->add_option("--services", a->services,
                  "Also record these services' introspection events (<service>/_service_event, as rosbag2's "
                  "--services), comma-separated or repeated (pause or /rbsim/pause); the node publishes them "
                  "once its parameter service_configure_introspection is metadata or contents")
      ->delimiter(',')
      ->allow_extra_args(false);
  app->add_flag(
      "--all-services", a->all_services,
      "Also record the introspection events of every service of the node (rosbag2's --all-services)");
  add_domain_option(app, a->domain);
  add_node_name_option(app, a->node);
  app->add_option("--namespace", a->rec.ns, "ROS namespace of the topics")
      ->check(ros_namespace())
      ->default_str("rbsim");
  app->add_option(
         "--wall-duration", a->duration,
         "Stop after this many seconds of wall-clock time (elsewhere in rbsim --duration is simulated "
         "time)")
      ->check(positive());
  // `--duration` means simulated seconds in every other command: here it would be wall time, so it
  // is refused with a pointer rather than taken in another sense.
  app->add_option("--duration", a->wrong_duration)->group("");
  app->add_option("--max-messages", a->rec.max_messages, "Stop after this many messages");
  app->add_option("--compression", a->compression, "MCAP chunk compression")
      ->check(CLI::IsMember({"zstd", "lz4", "none"}))
      ->default_str("zstd");
  app->add_option("--compression-level", a->compression_level,
                  "zstd -50..22 or lz4 0..12 (higher: smaller and slower); default zstd " +
                      std::to_string(kLiveZstdLevel) +
                      ", fast enough for a live stream (0: zstd 1, the MCAP C++ library's default, as rbsim "
                      "run --record)");
  app->add_option(
         "--chunk-size", a->rec.chunk_size,
         "Uncompressed bytes per MCAP chunk: a killed recorder loses at most the chunk it was filling and "
         "the one being compressed")
      ->check(CLI::Range(std::uint64_t{1024}, std::uint64_t{1} << 30))
      ->default_str("1048576");
  app->add_option("--max-file-size", a->rec.max_file_bytes,
                  "Bag only: start a new file once the open one holds this many bytes (as chunks reach it; "
                  "rosbag2's --max-bag-size)")
      ->check(CLI::Range(std::uint64_t{1} << 16, std::uint64_t{1} << 50));
  app->add_option("--max-file-duration", a->max_file_duration,
                  "Bag only: start a new file once the open one spans this many seconds of log (wall) time "
                  "(rosbag2's --max-bag-duration)")
      ->check(positive());
  app->add_option("--snapshot-duration", a->snapshot_duration,
                  "Snapshot mode (bag only): keep the last SECONDS of log time in memory (at most 1 GiB of "
                  "payload; the latched topics' latest always) and write them to the bag's next file on each "
                  "snapshot request (kill -USR1), as rosbag2's --snapshot-mode")
      ->check(positive());
  app->add_flag("-q,--quiet", a->quiet, "Only errors");
  app->add_flag("--overwrite", a->overwrite,
                "Replace OUT if it exists (by default an existing OUT is refused)");
  app->footer(
      "Writes the exact CDR payloads received: log_time = receive time, publish_time = the sample's source "
      "timestamp (ns since the Unix epoch). Ctrl-C or SIGTERM finishes a valid, indexed file and exits 0; a "
      "killed recorder leaves a file that 'rbsim log recover' repairs. Reports received and lost counts: "
      "lost "
      "is what DDS reports plus the steps missing from each per-step topic's sequence. The scene description "
      "is written first, whatever order discovery delivers the topics in.\n"
      "Exit status: 0 recorded (stopped by Ctrl-C/SIGTERM, --wall-duration or --max-messages), 1 error or "
      "nothing "
      "received (no file left), 2 usage error.");
  return {app, [a] { return record_command(*a); }};
}

namespace {
constexpr const char* kDdsEnvironmentHelp =
    "DDS environment, as for ROS 2 with rmw_cyclonedds_cpp: ROS_DOMAIN_ID is the domain when --domain is "
    "not given (else 0). ROS_AUTOMATIC_DISCOVERY_RANGE: LOCALHOST (default: rbsim's loopback "
    "configuration, 127.0.0.1 only, no multicast), SUBNET (Cyclone's network interface, multicast), "
    "OFF (no other process) or SYSTEM_DEFAULT (Cyclone's defaults). ROS_STATIC_PEERS=host;host adds "
    "unicast discovery peers (LOCALHOST, SUBNET). ROS_LOCALHOST_ONLY=1 (deprecated) means LOCALHOST and "
    "wins over both. CYCLONEDDS_URI, when set, configures everything but the domain id. An invalid value "
    "is an error naming the variable.";
}  // namespace

CLI::Option* add_domain_option(CLI::App* app, std::uint32_t& domain) {
  auto from_env = node::domain_from_environment(node::RosEnvironment::from_process());
  std::string shown = "0";
  if (!from_env) {
    domain = node::kDomainFromEnvironment;
    shown = "invalid ROS_DOMAIN_ID";
  } else if (from_env.value()) {
    domain = *from_env.value();
    shown = std::to_string(domain) + ", from ROS_DOMAIN_ID";
  } else {
    domain = 0;
  }
  app->footer([] { return std::string(kDdsEnvironmentHelp); });  // printed before the command's own footer
  return app
      ->add_option("--domain", domain,
                   "DDS domain id 0..232; wins over ROS_DOMAIN_ID (DDS environment below)")
      ->default_str(shown);
}

}  // namespace rbsim::cli
