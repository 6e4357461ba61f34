// rosbag2's bag directory, as ROS 2 Jazzy's recorder writes it with the mcap storage: DIR/metadata.yaml
// (what `ros2 bag info DIR` and the `rosbags` library open) beside the recording files DIR/DIR_0.mcap,
// DIR_1.mcap, ... An output path ending in ".mcap" is one file, as is an existing file (a script's
// temporary, replaced with --overwrite); any other path is a bag directory.
#pragma once

#include <cstddef>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "rbsim/mcap.hpp"
#include "rbsim/outputs.hpp"
#include "rbsim/status.hpp"

namespace rbsim::recordings {

inline constexpr std::string_view kBagMetadataFile = "metadata.yaml";
// The rosbag2 metadata version Jazzy writes (QoS policies by name).
inline constexpr int kBagMetadataVersion = 9;

// What a path names, by the one rule of every command that takes a recording, a bag or a scene
// (render and plot's input, run --commands, run --record's and record's OUT):
enum class PathKind {
  McapFile,      // any path ending in ".mcap", or an existing file starting with MCAP's magic
  BagDirectory,  // any other existing directory: a rosbag2 bag (its metadata.yaml lists its files)
  OtherFile,     // anything else that exists: a scene, a command script
  Missing,       // nothing there yet (as an output: a bag directory to create)
};
PathKind path_kind(std::string_view path);
// An input that is a recording rather than a scene or a script: an MCAP file or a bag directory.
bool is_recording(std::string_view path);
// An output that is a bag directory: an existing directory, or a new path not ending in ".mcap"
// (an existing file stays one file: a script's temporary, replaced with --overwrite).
bool is_bag_output(std::string_view path);
// The path of file `index` of bag `dir`: "runs/bag" -> "runs/bag/bag_0.mcap".
std::string bag_file(const std::string& dir, std::size_t index);

// What check_outputs() checks for bag `dir` given as `option`: the directory (its parent must
// exist) and, when it exists already, the files a recording writes into it (refused unless
// overwrite). Before writing, make_bag_directory() creates it.
std::vector<OutputPath> bag_outputs(const std::string& dir, const std::string& option);
[[nodiscard]] Status make_bag_directory(const std::string& dir);

// Writes `dir`/metadata.yaml (atomically: a reader sees the old or the new one) describing `files`
// (paths inside `dir`, in recording order) from their MCAP summaries: each topic's type, offered
// QoS and type hash (the channel metadata rosbag2's mcap storage writes) and message count, each
// file's start, duration and count, and the bag's. Fails naming a file that cannot be read.
[[nodiscard]] Status write_bag_metadata(const std::string& dir, const std::vector<std::string>& files);
// The same, file by file, for a writer that adds files as it closes them (a splitting recorder):
// add() reads a finished file's summary once, write() (re)writes `dir`/metadata.yaml atomically
// from every file added so far.
class BagMetadata {
 public:
  [[nodiscard]] Status add(const std::string& file);
  [[nodiscard]] Status write(const std::string& dir) const;

 private:
  struct Topic {
    std::string name, type, qos, hash;
    std::uint64_t count = 0;
  };
  struct File {
    std::string name;
    std::uint64_t start = 0, end = 0, count = 0;
  };
  std::vector<Topic> topics_;  // in the order first recorded
  std::vector<File> files_;
};

// The recording files `path` names: itself for a file; for a directory, the files its
// metadata.yaml lists, in order (errors name the directory and what is wrong: no metadata.yaml, a
// storage other than mcap, a listed file missing).
[[nodiscard]] Result<std::vector<std::string>> recording_files(const std::string& path);

// The one rule by which a bag of several files reads as one recording (rbsim's readers use it):
// a file after the first defines its channels under the ids the earlier files used, as rbsim record
// writes them (a bag whose files disagree is refused, naming the channel), and the latched messages
// a split repeats at the start of a file (on a transient-local channel, equal to the last message
// read on it, the first on it in its file) are read once.
class BagJoin {
 public:
  // A channel record of file `file` (0-based): `repeat` is set when an earlier file defined it.
  [[nodiscard]] Status channel(std::size_t file, const mcap::Channel& channel, bool& repeat);
  // True for a split's repeat of a latched message (to skip); call for every message, in order.
  bool repeated(std::size_t file, const mcap::Message& message);

 private:
  struct Known {
    std::string topic;
    bool latched = false;
    std::vector<std::byte> last;  // the last message on a latched channel
    std::size_t file = 0;         // the file it was read from
  };
  std::map<std::uint16_t, Known> channels_;
};

}  // namespace rbsim::recordings
