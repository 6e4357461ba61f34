// rosbag2 bag directories (rbsim/bag.hpp).
#include "rbsim/bag.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <filesystem>
#include <map>

#include "rbsim/atomic_file.hpp"
#include "rbsim/mcap.hpp"
#include "rbsim/mcap_records.hpp"
#include "rbsim/mcap_tools.hpp"

namespace rbsim::recordings {

namespace fs = std::filesystem;

namespace {

std::string value_of(const mcap::KeyValueMap& m, const std::string& key) {
  const auto it = m.find(key);
  return it == m.end() ? std::string() : it->second;
}

// The MCAP schema name "pkg/msg/Name" is rosbag2's topic type.
void emit_nanoseconds(YAML::Emitter& y, const char* key, const char* unit, std::uint64_t ns) {
  y << YAML::Key << key << YAML::Value << YAML::BeginMap << YAML::Key << unit << YAML::Value << ns
    << YAML::EndMap;
}

}  // namespace

PathKind path_kind(std::string_view path) {
  std::error_code ec;
  const fs::file_status status = fs::status(fs::path(path), ec);
  if (path.ends_with(".mcap")) return PathKind::McapFile;
  if (fs::is_directory(status)) return PathKind::BagDirectory;
  if (!fs::exists(status)) return PathKind::Missing;
  Result<std::unique_ptr<mcap::ByteSource>> source = mcap::open_file_source(std::string(path));
  return source.ok() && mcap::check_magic(*source.value(), 0).ok() ? PathKind::McapFile : PathKind::OtherFile;
}

bool is_recording(std::string_view path) {
  const PathKind kind = path_kind(path);
  return kind == PathKind::McapFile || kind == PathKind::BagDirectory;
}

bool is_bag_output(std::string_view path) {
  const PathKind kind = path_kind(path);
  return kind == PathKind::BagDirectory || kind == PathKind::Missing;
}

std::string bag_file(const std::string& dir, std::size_t index) {
  fs::path d(dir);
  if (!d.has_filename()) d = d.parent_path();  // "runs/bag/"
  return (d / (d.filename().string() + "_" + std::to_string(index) + ".mcap")).string();
}

std::vector<OutputPath> bag_outputs(const std::string& dir, const std::string& option) {
  std::vector<OutputPath> out{{dir, option, true}};
  std::error_code ec;
  if (fs::is_directory(dir, ec)) {
    out.push_back({(fs::path(dir) / kBagMetadataFile).string(), option});
    out.push_back({bag_file(dir, 0), option});
  }
  return out;
}

Status make_bag_directory(const std::string& dir) {
  std::error_code ec;
  fs::create_directory(dir, ec);
  if (ec) return Error{dir + ": cannot create the bag directory: " + ec.message(), ErrorCode::IoError};
  return Ok{};
}

Status BagMetadata::add(const std::string& file) {
  mcap::IndexedReader reader;
  if (Status st = reader.open(file); !st) return Error{file + ": " + mcap_tools::read_error(st.error())};
  File info{fs::path(file).filename().string()};
  const auto& stats = reader.statistics();
  if (stats) {
    info.start = stats->message_start_time;
    info.end = stats->message_end_time;
    info.count = stats->message_count;
  }
  for (const auto& [id, channel] : reader.channels()) {
    auto it =
        std::find_if(topics_.begin(), topics_.end(), [&](const Topic& t) { return t.name == channel.topic; });
    if (it == topics_.end()) {  // rosbag2 lists each topic once, as first recorded
      const auto schema = reader.schemas().find(channel.schema_id);
      topics_.push_back({channel.topic,
                         schema == reader.schemas().end() ? std::string() : schema->second.name,
                         value_of(channel.metadata, "offered_qos_profiles"),
                         value_of(channel.metadata, "topic_type_hash")});
      it = topics_.end() - 1;
    }
    if (stats) {
      if (const auto n = stats->channel_message_counts.find(id); n != stats->channel_message_counts.end())
        it->count += n->second;
    }
  }
  files_.push_back(std::move(info));
  return Ok{};
}

Status write_bag_metadata(const std::string& dir, const std::vector<std::string>& files) {
  BagMetadata metadata;
  for (const std::string& file : files) {
    if (Status st = metadata.add(file); !st) return st;
  }
  return metadata.write(dir);
}

Status BagMetadata::write(const std::string& dir) const {
  std::uint64_t start = 0, end = 0, count = 0;
  bool any = false;
  for (const File& f : files_) {
    count += f.count;
    if (f.count == 0) continue;
    start = any ? std::min(start, f.start) : f.start;
    end = any ? std::max(end, f.end) : f.end;
    any = true;
  }
  YAML::Emitter y;
  y << YAML::BeginMap << YAML::Key << "rosbag2_bagfile_information" << YAML::Value << YAML::BeginMap;
  y << YAML::Key << "version" << YAML::Value << kBagMetadataVersion;
  y << YAML::Key << "storage_identifier" << YAML::Value << "mcap";
  emit_nanoseconds(y, "duration", "nanoseconds", end - start);
  emit_nanoseconds(y, "starting_time", "nanoseconds_since_epoch", start);
  y << YAML::Key << "message_count" << YAML::Value << count;
  y << YAML::Key << "topics_with_message_count" << YAML::Value << YAML::BeginSeq;
  for (const Topic& t : topics_) {
    const std::string& name = t.name;
    y << YAML::BeginMap << YAML::Key << "topic_metadata" << YAML::Value << YAML::BeginMap;
    y << YAML::Key << "name" << YAML::Value << name << YAML::Key << "type" << YAML::Value << t.type;
    y << YAML::Key << "serialization_format" << YAML::Value << "cdr";
    y << YAML::Key << "offered_qos_profiles" << YAML::Value << YAML::Literal << t.qos;
    y << YAML::Key << "type_description_hash" << YAML::Value << t.hash << YAML::EndMap;
    y << YAML::Key << "message_count" << YAML::Value << t.count << YAML::EndMap;
  }
  y << YAML::EndSeq;
  y << YAML::Key << "compression_format" << YAML::Value << "" << YAML::Key << "compression_mode"
    << YAML::Value << "";
  y << YAML::Key << "relative_file_paths" << YAML::Value << YAML::BeginSeq;
  for (const File& f : files_) y << f.name;
  y << YAML::EndSeq << YAML::Key << "files" << YAML::Value << YAML::BeginSeq;
  for (const File& f : files_) {
    y << YAML::BeginMap << YAML::Key << "path" << YAML::Value << f.name;
    emit_nanoseconds(y, "starting_time", "nanoseconds_since_epoch", f.start);
    emit_nanoseconds(y, "duration", "nanoseconds", f.end - f.start);
    y << YAML::Key << "message_count" << YAML::Value << f.count << YAML::EndMap;
  }
  y << YAML::EndSeq << YAML::Key << "custom_data" << YAML::Value << YAML::Null;
  y << YAML::Key << "ros_distro" << YAML::Value << "jazzy" << YAML::EndMap << YAML::EndMap;
  const std::string text = std::string(y.c_str()) + "\n";
  AtomicFile out;
  if (Status st = out.open((fs::path(dir) / kBagMetadataFile).string()); !st) return st;
  if (Status st = out.write(text.data(), text.size()); !st) return st;
  return out.commit();
}

Result<std::vector<std::string>> recording_files(const std::string& path) {
  std::error_code ec;
  if (!fs::is_directory(path, ec)) return std::vector<std::string>{path};
  const fs::path metadata = fs::path(path) / kBagMetadataFile;
  if (!fs::exists(metadata, ec)) {
    return Error{path + ": a directory without " + std::string(kBagMetadataFile) + ": not a rosbag2 bag"};
  }
  try {
    const YAML::Node root = YAML::LoadFile(metadata.string());
    const YAML::Node info = root["rosbag2_bagfile_information"];
    if (!info) return Error{metadata.string() + ": no rosbag2_bagfile_information"};
    const std::string storage =
        info["storage_identifier"] ? info["storage_identifier"].as<std::string>() : "";
    if (storage != "mcap") {
      return Error{metadata.string() + ": storage_identifier \"" + storage +
                   "\": rbsim reads mcap bags only"};
    }
    std::vector<std::string> files;
    for (const YAML::Node& f : info["relative_file_paths"]) {
      const fs::path file = fs::path(path) / fs::path(f.as<std::string>()).filename();
      if (!fs::exists(file, ec))
        return Error{metadata.string() + ": lists " + file.string() + ", which is missing"};
      files.push_back(file.string());
    }
    if (files.empty()) return Error{metadata.string() + ": relative_file_paths lists no file"};
    return files;
  } catch (const YAML::Exception& e) {
    return Error{metadata.string() + ":" + std::to_string(e.mark.line + 1) + ": " + e.msg};
  }
}

Status BagJoin::channel(std::size_t file, const mcap::Channel& channel, bool& repeat) {
  const auto [it, fresh] = channels_.try_emplace(channel.id);
  repeat = !fresh;
  if (fresh) {
    it->second.topic = channel.topic;
    it->second.latched =
        value_of(channel.metadata, "offered_qos_profiles").find("durability: transient_local") !=
        std::string::npos;
    return Ok{};
  }
  if (it->second.topic != channel.topic) {
    return Error{"file " + std::to_string(file) + " of the bag defines channel " +
                 std::to_string(channel.id) + " as " + channel.topic + ", an earlier one as " +
                 it->second.topic +
                 ": rbsim reads bags whose files share their channel ids (as rbsim record writes them)"};
  }
  return Ok{};
}

bool BagJoin::repeated(std::size_t file, const mcap::Message& message) {
  const auto it = channels_.find(message.channel_id);
  if (it == channels_.end() || !it->second.latched) return false;
  Known& k = it->second;
  // Only a file's first message on the channel can be a split's copy (a --loop pass may publish
  // the same scene description again later, which is kept).
  const bool same = file > 0 && k.file != file && !k.last.empty() &&
                    std::equal(k.last.begin(), k.last.end(), message.data.begin(), message.data.end());
  k.file = file;
  if (!same) k.last.assign(message.data.begin(), message.data.end());
  return same;
}

}  // namespace rbsim::recordings
