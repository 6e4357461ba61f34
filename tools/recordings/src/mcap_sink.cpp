// Recording a run to MCAP.
#include <array>
#include <string>

#include "rbsim/atomic_file.hpp"
#include "rbsim/mcap_sink.hpp"

#include "rbsim/bag.hpp"
#include "rbsim/type_hash.hpp"

namespace rbsim::recordings {

namespace {

Error fail(const std::string& path, const Error& error) {
  return Error{path + ": " + error.message};
}

class McapFileSink final : public McapSink {
 public:
  // A path not ending in ".mcap" is a bag directory: the recording is its file 0 and finish()
  // writes its metadata.yaml.
  McapFileSink(std::string path, McapSinkOptions options)
      : path_(std::move(path)), options_(std::move(options)), ids_(msgs::topic_ids(options_.topics)) {
    if (is_bag_output(path_)) {
      bag_ = path_;
      path_ = bag_file(bag_, 0);
    }
  }

  Status begin(const Scene& scene, const World& world) override {
    if (options_.every < 1) {
      return Error{path_ + ": record every " + std::to_string(options_.every) + " steps: must be at least 1"};
    }
    encoder_ = std::make_unique<msgs::Encoder>(scene, options_.ns);
    dt_ = scene.world.dt;
    // Written under a temporary name and renamed into place by finish(): a killed run leaves the
    // temporary (`<path>.tmp.<pid>`), which `rbsim log recover` turns into a recording.
    if (!bag_.empty()) {
      if (Status st = make_bag_directory(bag_); !st) return st;
    }
    file_.open_external(path_);
    if (auto st = writer_.open(file_.writer_path(), writer_options(options_.compression, options_.chunk_size,
                                                                   options_.compression_level));
        !st.ok()) {
      return fail(path_, st.error());
    }
    for (msgs::TopicId id : ids_) {
      auto channel = add_topic(writer_, msgs::topic(id), options_.ns);
      if (!channel.ok()) return fail(path_, channel.error());
      channels_[static_cast<std::size_t>(id)] = channel.value();
    }
    return record(world, true);
  }

  Status write(const World& world) override {
    if (world.step_index() % options_.every != 0) return Ok{};
    return record(world, false);
  }

  Status record_command(std::span<const std::byte> cdr, std::int64_t step) override {
    constexpr auto k = static_cast<std::size_t>(msgs::TopicId::Commands);
    if (channels_[k] == 0) {  // added with the first command: a run without any has no such channel
      auto channel = add_topic(writer_, msgs::topic(msgs::TopicId::Commands), options_.ns);
      if (!channel.ok()) return fail(path_, channel.error());
      channels_[k] = channel.value();
    }
    const mcap::Timestamp sim = msgs::sim_time_ns(step, dt_), t = log_time(sim);
    if (auto st = writer_.write_message(channels_[k], sequence_[k]++, t, sim, cdr); !st.ok()) {
      return fail(path_, st.error());
    }
    return Ok{};
  }

  bool follows_structure() const override { return true; }
  // Bodies came or went at this step's boundary: the scene description and markers again (the
  // markers led by a DELETEALL), then this step's per-step topics with the new arrays, at this
  // step's time, as the node's DDS sink publishes them, so a re-run records the live bytes.
  // A world loaded (Entities::world) is recorded the same way, from its step 0: its scene
  // description starts the epoch, at a step lower than the last one's.
  Status restructure(const World& world, const Entities& entities) override {
    encoder_->restructure(entities);
    dt_ = world.dt();
    return record(world, true);
  }

  Status finish() override {
    if (auto st = writer_.close(); !st.ok()) return fail(path_, st.error());
    if (Status st = file_.commit(); !st) return st;
    return bag_.empty() ? Status(Ok{}) : write_bag_metadata(bag_, {path_});
  }

 private:
  Status record(const World& world, bool first) {
    const mcap::Timestamp sim = msgs::sim_time_ns(world), t = log_time(sim);
    for (msgs::TopicId id : ids_) {  // in topics() order: the latched ones first
      const msgs::TopicSpec& spec = msgs::topic(id);
      if (!spec.per_step && !first) continue;
      encoder_->encode(id, world, buffer_);
      const auto k = static_cast<std::size_t>(id);
      if (auto st = writer_.write_message(channels_[k], sequence_[k]++, t, sim, buffer_); !st.ok()) {
        return fail(path_, st.error());
      }
    }
    return Ok{};
  }

  // Log time is the session's simulated time: the world's, plus the time of the worlds before it
  // when the steps start again (a reset, a world loaded: rbsim/recording.hpp's segments), so log
  // times never go back and a reader in log-time order reads the session in its order. Publish
  // time stays the world's own.
  mcap::Timestamp log_time(mcap::Timestamp sim) {
    if (sim + offset_ < last_) offset_ = last_ - sim;
    last_ = sim + offset_;
    return last_;
  }

  std::string path_;
  std::string bag_;  // the bag directory, if the output is one
  McapSinkOptions options_;
  std::vector<msgs::TopicId> ids_;  // the selected topics
  AtomicFile file_;  // declared before writer_: the writer closes before the temporary is removed
  mcap::Writer writer_;
  std::unique_ptr<msgs::Encoder> encoder_;
  double dt_ = 0.0;
  mcap::Timestamp offset_ = 0, last_ = 0;  // log_time()'s
  std::array<std::uint16_t, msgs::kTopicCount> channels_{};
  std::array<std::uint32_t, msgs::kTopicCount> sequence_{};
  msgs::Bytes buffer_;
};

}  // namespace

mcap::WriterOptions writer_options(mcap::Compression compression, std::uint64_t chunk_size,
                                   int compression_level) {
  mcap::WriterOptions o;
  o.profile = "ros2";
  o.library = std::string("rbsim ") + version();
  o.compression = compression;
  o.compression_level = compression_level;
  o.chunk_size = chunk_size;
  // Recordings compress beside the simulation or DDS reception that feeds them (same bytes).
  o.background_compression = true;
  return o;
}

Result<std::uint16_t> add_topic(mcap::Writer& writer, const msgs::TopicSpec& spec, std::string_view ns) {
  return add_topic(writer, spec, ns, msgs::offered_qos(spec));
}

Result<std::uint16_t> add_topic(mcap::Writer& writer, const msgs::TopicSpec& spec, std::string_view ns,
                                const msgs::OfferedQos& offered) {
  return add_topic(writer, msgs::topic_name(spec, ns), spec.type, offered);
}

Result<std::uint16_t> add_topic(mcap::Writer& writer, std::string_view ros_name, std::string_view ros_type,
                                const msgs::OfferedQos& offered) {
  Result<std::string> schema = msgs::ros2msg_schema(ros_type);
  if (!schema) return schema.error();
  const std::string& text = schema.value();
  auto schema_id = writer.add_schema(ros_type, "ros2msg", std::as_bytes(std::span(text)));
  if (!schema_id.ok()) return schema_id.error();
  // rosbag2_storage_mcap (Jazzy) writes the topic's type hash as channel metadata "topic_type_hash".
  Result<std::string> hash = msgs::type_hash(ros_type);
  if (!hash) return hash.error();
  return writer.add_channel(
      schema_id.value(), ros_name, "cdr",
      {{"offered_qos_profiles", msgs::offered_qos_yaml(offered)}, {"topic_type_hash", hash.value()}});
}

std::unique_ptr<McapSink> make_mcap_sink(std::string path, McapSinkOptions options) {
  return std::make_unique<McapFileSink>(std::move(path), std::move(options));
}

}  // namespace rbsim::recordings
