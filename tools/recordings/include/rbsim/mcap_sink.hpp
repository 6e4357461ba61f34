// Recording a run to MCAP: the MCAP sink of `rbsim run --record` (the DDS recorder of `rbsim
// record` is node/'s recorder) and the conventions every rbsim recording follows, the rosbag2
// layout (profile "ros2", "ros2msg" schemas, "cdr" messages, "offered_qos_profiles" and
// "topic_type_hash" channel metadata), so Foxglove and `ros2 bag` open them.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "rbsim/mcap.hpp"
#include "rbsim/msgs.hpp"
#include "rbsim/sink.hpp"

namespace rbsim::recordings {

struct McapSinkOptions {
  mcap::Compression compression = mcap::Compression::Zstd;
  int compression_level = 0;           // 0: the codec's default (check_compression_level)
  std::uint64_t chunk_size = 1 << 20;  // uncompressed bytes per chunk
  std::int64_t every = 1;              // record every k-th step (step 0 always); begin() refuses < 1
  std::string ns = "rbsim";            // ROS namespace of the topics
  msgs::TopicSet topics = msgs::default_topics();
};

// A Sink that records a run: every selected latched topic (scene description, markers) once at
// step 0, then every selected per-step topic at step 0 and every k-th step after it. It follows a
// world whose bodies change: at a change, every selected topic again at that step (the latched
// ones first), so a recording holds one epoch per scene description (rbsim/recording.hpp).
// log_time = publish_time = simulated time in ns, so a recording is deterministic; where the steps
// start again (a reset, a world loaded) log time goes on from where it was (the session's
// simulated time) and publish time is the world's.
class McapSink : public Sink {
 public:
  // A steered run's commands: one rbsim_msgs/msg/Command (CDR) on /<ns>/commands at the simulated
  // time of the step it applied at, written between steps (after that step's messages); the
  // channel is added with the first. Every command is recorded, whatever --record-every says.
  [[nodiscard]] virtual Status record_command(std::span<const std::byte> cdr, std::int64_t step) = 0;
};
std::unique_ptr<McapSink> make_mcap_sink(std::string path, McapSinkOptions options = {});

// Adds the schema and channel of `spec` to a writer in the rosbag2 layout; returns the channel id.
// The channel's offered_qos_profiles say `offered` (by default what rbsim's node offers); its
// topic_type_hash is msgs::type_hash(spec.type), where rosbag2 (Jazzy) writes it. The one place
// channel metadata is written: the MCAP sink and the DDS recorder both come here.
Result<std::uint16_t> add_topic(mcap::Writer& writer, const msgs::TopicSpec& spec, std::string_view ns,
                                const msgs::OfferedQos& offered);
Result<std::uint16_t> add_topic(mcap::Writer& writer, const msgs::TopicSpec& spec, std::string_view ns);
// The same for a topic by its ROS name and type ("/rbsim/pause/_service_event",
// "std_srvs/srv/Trigger_Event": any type msgs::ros2msg_schema and msgs::type_hash know).
Result<std::uint16_t> add_topic(mcap::Writer& writer, std::string_view ros_name, std::string_view ros_type,
                                const msgs::OfferedQos& offered);
// The writer options of every rbsim log (profile "ros2", library "rbsim <version>").
mcap::WriterOptions writer_options(mcap::Compression compression, std::uint64_t chunk_size = 1 << 20,
                                   int compression_level = 0);

}  // namespace rbsim::recordings
