// Whether a path is an MCAP file, a bag directory or something else (recordings::path_kind): the one
// rule of render/plot's input, run --commands, run --record's and record's OUT.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "rbsim/bag.hpp"
#include "rbsim/subprocess.hpp"

namespace rbsim::recordings {
namespace {

namespace fs = std::filesystem;

void write(const fs::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

TEST(PathKind, ByNameMagicAndWhatExists) {
  test::TempDir dir;
  const std::string magic = "\x89MCAP0\r\n";
  write(dir / "run.bin", magic + "the rest");       // a recording under another name
  write(dir / "scene.xml", "<scene/>");             // a scene
  write(dir / "short", "\x89MC");                   // too short for the magic
  write(dir / "damaged.mcap", "not an MCAP file");  // named as one: read as one (and refused)
  fs::create_directory(dir / "bag");
  fs::create_directory(dir / "odd.mcap");
  EXPECT_EQ(path_kind((dir / "run.bin").string()), PathKind::McapFile);
  EXPECT_EQ(path_kind((dir / "damaged.mcap").string()), PathKind::McapFile);
  EXPECT_EQ(path_kind((dir / "new.mcap").string()), PathKind::McapFile);  // missing, but named so
  EXPECT_EQ(path_kind((dir / "odd.mcap").string()), PathKind::McapFile);  // the name decides first
  EXPECT_EQ(path_kind((dir / "bag").string()), PathKind::BagDirectory);
  EXPECT_EQ(path_kind((dir / "bag").string() + "/"), PathKind::BagDirectory);
  EXPECT_EQ(path_kind((dir / "scene.xml").string()), PathKind::OtherFile);
  EXPECT_EQ(path_kind((dir / "short").string()), PathKind::OtherFile);
  EXPECT_EQ(path_kind((dir / "new_bag").string()), PathKind::Missing);
}

TEST(PathKind, InputsAndOutputsReadTheSameKinds) {
  test::TempDir dir;
  write(dir / "run.bin", std::string("\x89MCAP0\r\n") + "rest");
  write(dir / "steer.yaml", "- {step: 1, pause: true}\n");
  fs::create_directory(dir / "bag");
  // As an input: a recording is an MCAP file or a bag; anything else is a scene or a script.
  EXPECT_TRUE(is_recording((dir / "run.bin").string()));
  EXPECT_TRUE(is_recording((dir / "bag").string()));
  EXPECT_TRUE(is_recording((dir / "x.mcap").string()));
  EXPECT_FALSE(is_recording((dir / "steer.yaml").string()));
  EXPECT_FALSE(is_recording((dir / "missing.xml").string()));
  // As an output: a bag directory unless named .mcap or already a file.
  EXPECT_TRUE(is_bag_output((dir / "bag").string()));
  EXPECT_TRUE(is_bag_output((dir / "new_bag").string()));
  EXPECT_FALSE(is_bag_output((dir / "x.mcap").string()));
  EXPECT_FALSE(is_bag_output((dir / "run.bin").string()));
  EXPECT_FALSE(is_bag_output((dir / "steer.yaml").string()));
}

}  // namespace
}  // namespace rbsim::recordings
