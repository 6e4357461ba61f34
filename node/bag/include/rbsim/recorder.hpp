// rbsim record: DDS topics into an MCAP recording.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <deque>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "rbsim/bag.hpp"
#include "rbsim/mcap.hpp"
#include "rbsim/middleware.hpp"

namespace rbsim::bag {

// The recorder: subscribes to rbsim topics and writes the exact CDR payloads to MCAP (rosbag2
// layout), log_time = receive time, publish_time = the sample's source timestamp (both ns since
// the Unix epoch). Chunks are flushed as they fill, so a killed recorder leaves a file
// `rbsim log recover` repairs.
//
// Lost messages are what DDS reports lost or rejected plus the gaps the recorder sees in the
// steps of each per-step topic: every per-step message carries its simulated time (header stamp,
// or the clock), the scene description gives dt, so each message names its step; the node
// publishes every k-th step, so within one run of the scene (a --loop restarts it) the steps
// received on a topic are first, first + k, ..., last, and the ones missing from that sequence
// were lost, e.g. while a link was down for longer than the DDS lease and the reader was
// dropped (messages that DDS itself never reports). k is the smallest step difference seen.

struct RecorderOptions {
  std::string path;  // the file; with `bag`, ignored: the files are the bag's
  // A rosbag2 bag directory (rbsim/bag.hpp), made already: files bag_0.mcap, bag_1.mcap, ... and
  // metadata.yaml, rewritten (atomically) at every split listing the closed files, and at close().
  std::string bag;
  // Splits (bag only; 0: none): a new file once the open one holds this many bytes (checked as
  // chunks reach it) or spans this much log time. Every file starts with the latest scene
  // description and markers (each file is readable and drawable alone) and defines the channels
  // under the same ids as the files before it.
  std::uint64_t max_file_bytes = 0;
  std::uint64_t max_file_duration_ns = 0;
  // Snapshot mode (bag only; 0: off): nothing is written as it arrives; the last this-many ns of
  // log time are kept in memory (at most snapshot_max_bytes of payload, oldest dropped first; the
  // latched topics' latest messages always), and each snapshot() writes them to the bag's next file.
  std::uint64_t snapshot_duration_ns = 0;
  std::uint64_t snapshot_max_bytes = std::uint64_t{1} << 30;
  std::string ns = "rbsim";
  // Which topics, as rosbag2's recorder chooses: those named in `topics` ("body_states" or
  // "/rbsim/body_states") and those whose full name matches `regex` (ECMAScript, the whole name),
  // every topic when both are empty; minus those named in `exclude_topics` or matching
  // `exclude_regex`.
  std::vector<std::string> topics;
  std::string regex;
  std::vector<std::string> exclude_topics;
  std::string exclude_regex;
  // Topics outside msgs::topics() by their ROS name and type, recorded as they arrive (after the
  // latched topics, as the per-step ones; no step checks; subscribed volatile, so what was
  // published before the recorder matched is not there): the _service_event topics of the node's
  // services (rbsim record --services, --all-services), as rosbag2 records a service's events.
  std::vector<node::RawTopic> raw_topics;
  mcap::Compression compression = mcap::Compression::Zstd;
  int compression_level = 0;  // 0: the codec's default
  std::uint64_t chunk_size = 1 << 20;
  std::uint64_t max_messages = 0;  // 0: no limit
};

class Recorder {
 public:
  static Result<std::unique_ptr<Recorder>> create(const node::Participant& participant,
                                                  const RecorderOptions& options);
  ~Recorder();
  // Waits up to `timeout_ns` for data and records everything available; true if anything came.
  Result<bool> poll(std::int64_t timeout_ns);
  [[nodiscard]] Status close();  // finishes a valid, indexed file (and a bag's metadata)
  // Snapshot mode: writes what is kept (latched topics first) to the bag's next file, lists it in
  // metadata.yaml and empties the buffer; returns the messages written (0: nothing was kept, no file).
  Result<std::uint64_t> snapshot();
  // A new file now (bag only, not in snapshot mode), as a split does.
  [[nodiscard]] Status split_now();
  // Paused: samples are still taken from DDS (nobody waits on us) but not recorded. Any thread.
  void set_paused(bool paused) { paused_.store(paused, std::memory_order_relaxed); }
  bool paused() const { return paused_.load(std::memory_order_relaxed); }
  std::uint64_t skipped_paused() const { return skipped_paused_; }
  std::uint64_t received() const { return received_; }
  // The files written so far (the last one open until close()); one unless a bag was split.
  const std::vector<std::string>& files() const { return files_; }
  struct TopicCount {
    std::string topic;
    std::uint64_t received = 0, lost = 0;  // lost: reported by DDS plus gaps in the steps
    std::uint64_t duplicates = 0;          // samples delivered again, not recorded twice
  };
  std::vector<TopicCount> counts() const;

 private:
  Recorder() = default;
  // Steps received on one per-step topic since the scene (re)started, as simulated times in ns
  // (converted with dt once the scene description is known).
  struct Gaps {
    std::int64_t first = -1, last = -1, stride = 0;  // ns; stride: smallest difference seen
    std::uint64_t count = 0;                         // messages in this run of the scene
    std::uint64_t lost_before = 0;                   // in earlier runs (--loop)
    void add(std::int64_t stamp_ns, double dt);
    std::uint64_t lost(double dt) const;
  };
  struct Topic {
    node::Subscription subscription;
    const node::RawTopic* raw;  // one of options_.raw_topics, or null for one of msgs::topics()
    std::uint16_t channel;      // 0 until the first sample: its writer's QoS goes into the channel
    std::uint32_t received;
    msgs::OfferedQos offered{};  // what its channel says (the first publisher's offer)
    // A latched topic's latest sample (payload and times), written again at the start of every
    // later file of a split bag.
    msgs::Bytes last{};
    std::uint64_t last_source = 0;
    Gaps gaps;
    // Per writer, the newest source timestamp recorded. A sample not newer than that is one
    // delivered again: after a reconnection DDS can resend what a reader already had (seen when
    // a link came back after the lease expired), and a log must hold each message once.
    std::vector<std::pair<std::array<std::uint8_t, 16>, std::int64_t>> newest{};
    std::uint64_t duplicates = 0;
    bool latched_pending = false;  // latched, and nothing came on it yet
  };
  RecorderOptions options_;
  mcap::Writer writer_;
  std::vector<std::string> files_;
  std::atomic<bool> paused_{false};
  std::uint64_t skipped_paused_ = 0;
  std::vector<std::size_t> channel_order_;  // topics_ indices in the order their channels were added
  std::uint64_t file_start_ = 0;            // log time of the open file's first message (0: none yet)
  std::uint64_t file_bytes_ = 0;            // the open file's size as last seen (every 16 messages)
  std::uint64_t written_ = 0;
  [[nodiscard]] Status open_file();
  [[nodiscard]] Status close_bag_file();
  recordings::BagMetadata bag_metadata_;  // the bag's closed files
  [[nodiscard]] Status split(std::uint64_t log_time);
  [[nodiscard]] Status add_channels();
  [[nodiscard]] Result<std::uint16_t> add_channel(const Topic& t, const msgs::OfferedQos& offered);
  static bool is_latched(const Topic& t) { return t.raw == nullptr && t.subscription.spec().latched(); }
  static bool is_scene(const Topic& t) {
    return t.raw == nullptr && t.subscription.spec().id == msgs::TopicId::SceneDescription;
  }
  // Snapshot mode's buffer: per-step and event messages in arrival order.
  struct Kept {
    std::size_t topic;
    msgs::Bytes cdr;
    std::uint64_t log_time, source;
    std::uint32_t sequence;
  };
  std::deque<Kept> kept_;
  std::uint64_t kept_bytes_ = 0;
  std::uint64_t snapshot_dropped_ = 0;  // for the end line: dropped to keep within the bounds
  void keep(Topic& t, const node::Received& sample, std::uint64_t log_time, std::uint64_t source);

 public:
  std::uint64_t snapshot_dropped() const { return snapshot_dropped_; }

 private:
  node::WaitSet waitset_;
  std::vector<Topic> topics_;
  std::uint64_t received_ = 0;
  double dt_ = 0.0;  // from the scene description; 0 until it arrives

  // The latched topics (scene description, markers) are written first, whatever order discovery
  // delivers the topics in: per-step samples that arrive before them are held (at most kHoldNs of
  // wall time and kHoldBytes of payload), then written after them, the scene description first.
  // Held samples wait for the scene description, and for the markers only while a publisher of
  // them is matched (a node run with
  // --topics may not publish them). A latched sample written while samples are held takes the log
  // time of the first held one, so the file stays in log-time order.
  static constexpr std::uint64_t kHoldNs = 3'000'000'000;
  static constexpr std::uint64_t kHoldBytes = std::uint64_t{64} << 20;
  std::uint64_t held_bytes_ = 0;
  struct Held {
    std::size_t topic;
    node::Received sample;
    std::uint64_t log_time;
  };
  bool holding_ = false;  // a latched topic is recorded and has not delivered yet
  [[nodiscard]] bool latched_outstanding() const;
  [[nodiscard]] bool scene_pending() const;
  std::vector<Held> held_;
  [[nodiscard]] Status write(Topic& topic, const node::Received& sample, std::uint64_t log_time);
  [[nodiscard]] Status release_held();
};

// The recorder's services, as rosbag2's recorder node offers them under its name
// (/rbsim_recorder/...): pause, resume, is_paused (rosbag2_interfaces' Pause, Resume, IsPaused),
// split_bagfile (SplitBagfile) and snapshot (Snapshot), served on their own thread. Pause and resume
// take effect at once; a split or a snapshot is carried out by the recording loop at its next
// carry_out() (it polls every 100 ms) and answered then, or after 5 s unsuccessfully (Snapshot's
// success false; SplitBagfile's reply has no field to say so). A snapshot outside snapshot mode, or
// a split of one .mcap file or in snapshot mode, fails (success false; the split is not made).
class RecorderServices {
 public:
  static Result<std::unique_ptr<RecorderServices>> create(const node::Participant& participant,
                                                          Recorder& recorder);
  ~RecorderServices();
  RecorderServices(const RecorderServices&) = delete;
  RecorderServices& operator=(const RecorderServices&) = delete;
  // The recording loop's thread: carries out the splits and snapshots asked for since the last
  // call, and one more snapshot with `snapshot` (SIGUSR1), and says what it did on stderr (unless
  // quiet). A failure to write is returned.
  [[nodiscard]] Status carry_out(bool quiet, bool snapshot = false);

 private:
  RecorderServices() = default;
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rbsim::bag
