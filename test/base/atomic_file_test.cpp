// AtomicFile: the output appears only on commit(), whole; anything else leaves the old file as it
// was and no temporary behind.
#include "rbsim/atomic_file.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace rbsim {
namespace {

namespace fs = std::filesystem;

class AtomicFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("rbsim_atomic_file_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  std::vector<std::string> names() const {
    std::vector<std::string> out;
    for (const auto& e : fs::directory_iterator(dir_)) out.push_back(e.path().filename().string());
    std::sort(out.begin(), out.end());
    return out;
  }
  static std::string read(const std::string& p) {
    std::ifstream f(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(f), {}};
  }
  static void write_text(const std::string& p, const std::string& text) {
    std::ofstream(p, std::ios::binary) << text;
  }

  fs::path dir_;
};

TEST_F(AtomicFileTest, CommitMovesTheWholeFileIntoPlace) {
  AtomicFile f;
  ASSERT_TRUE(f.open(path("out.csv")).ok());
  EXPECT_EQ(f.temp_path(), path("out.csv") + ".tmp." + std::to_string(::getpid()));
  ASSERT_TRUE(f.write("a,b\n", 4).ok());
  ASSERT_TRUE(f.write("1,2\n", 4).ok());
  EXPECT_EQ(f.bytes_written(), 8u);
  EXPECT_EQ(names(), std::vector<std::string>{"out.csv.tmp." + std::to_string(::getpid())});
  ASSERT_TRUE(f.commit().ok());
  EXPECT_EQ(names(), std::vector<std::string>{"out.csv"});
  EXPECT_EQ(read(path("out.csv")), "a,b\n1,2\n");
}

TEST_F(AtomicFileTest, RenameOnlyCommitAlsoMovesTheWholeFileIntoPlace) {
  write_text(path("frame00001.png"), "old");
  AtomicFile f;
  ASSERT_TRUE(f.open(path("frame00001.png")).ok());
  ASSERT_TRUE(f.write("new frame", 9).ok());
  EXPECT_EQ(read(path("frame00001.png")), "old");
  ASSERT_TRUE(f.commit(AtomicFile::Durability::RenameOnly).ok());
  EXPECT_EQ(names(), std::vector<std::string>{"frame00001.png"});
  EXPECT_EQ(read(path("frame00001.png")), "new frame");
}

TEST_F(AtomicFileTest, DestroyedUncommittedKeepsTheOldFileAndRemovesTheTemporary) {
  write_text(path("out.csv"), "old");
  {
    AtomicFile f;
    ASSERT_TRUE(f.open(path("out.csv")).ok());
    ASSERT_TRUE(f.write("new", 3).ok());
  }
  EXPECT_EQ(names(), std::vector<std::string>{"out.csv"});
  EXPECT_EQ(read(path("out.csv")), "old");
}

TEST_F(AtomicFileTest, DiscardRemovesTheTemporary) {
  AtomicFile f;
  ASSERT_TRUE(f.open(path("out.bin")).ok());
  f.discard();
  EXPECT_TRUE(names().empty());
  Status st = f.commit();
  ASSERT_FALSE(st.ok());
  EXPECT_EQ(st.error().message, path("out.bin") + ": commit of a file that is not open");
}

TEST_F(AtomicFileTest, OpenInAMissingFolderNamesThePath) {
  AtomicFile f;
  Status st = f.open(path("no/such/out.csv"));
  ASSERT_FALSE(st.ok());
  EXPECT_EQ(st.error().message,
            path("no/such/out.csv") + ": cannot create output file: No such file or directory");
  EXPECT_FALSE(f.write("x", 1).ok());
}

TEST_F(AtomicFileTest, StreamWritesThroughTheSameTemporary) {
  AtomicFile f;
  ASSERT_TRUE(f.open(path("out.txt")).ok());
  ASSERT_NE(f.stream(), nullptr);
  std::fputs("through FILE*", f.stream());
  ASSERT_TRUE(f.commit().ok());
  EXPECT_EQ(read(path("out.txt")), "through FILE*");
}

TEST_F(AtomicFileTest, OpenExternalCommitsWhatTheWriterCreated) {
  AtomicFile f;
  f.open_external(path("movie.mp4"));
  EXPECT_EQ(f.stream(), nullptr);
  EXPECT_TRUE(names().empty());  // the writer creates it, not AtomicFile
  write_text(f.temp_path(), "frames");
  ASSERT_TRUE(f.commit().ok());
  EXPECT_EQ(names(), std::vector<std::string>{"movie.mp4"});
  EXPECT_EQ(read(path("movie.mp4")), "frames");
}

TEST_F(AtomicFileTest, OpenExternalWithoutAFileFailsAndLeavesTheOldOne) {
  write_text(path("plot.png"), "old");
  AtomicFile f;
  f.open_external(path("plot.png"));
  Status st = f.commit();
  ASSERT_FALSE(st.ok());
  EXPECT_EQ(st.error().message, path("plot.png") + ": write failed: No such file or directory");
  EXPECT_EQ(read(path("plot.png")), "old");
}

TEST_F(AtomicFileTest, OpenExternalDestroyedRemovesTheWritersFile) {
  {
    AtomicFile f;
    f.open_external(path("run.mcap"));
    write_text(f.temp_path(), "half a recording");
  }
  EXPECT_TRUE(names().empty());
}

}  // namespace
}  // namespace rbsim
