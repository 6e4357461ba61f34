// AtomicFile: the output appears only on commit(), whole; anything else leaves the old file as it
// was and no temporary behind.
#include "rbsim/atomic_file.hpp"

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstring>

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
  EXPECT_EQ(f.temp_path(), "") << "unnamed until commit (O_TMPFILE)";
  ASSERT_TRUE(f.write("a,b\n", 4).ok());
  ASSERT_TRUE(f.write("1,2\n", 4).ok());
  EXPECT_EQ(f.bytes_written(), 8u);
  EXPECT_TRUE(names().empty()) << testing::PrintToString(names());
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

// O_TMPFILE (every file system the suite runs on has it: ext4, tmpfs, overlayfs): while it is
// written, the output has no name at all.
TEST_F(AtomicFileTest, OpenWritesAnUnnamedFileUntilCommit) {
  AtomicFile f;
  ASSERT_TRUE(f.open(path("out.csv")).ok());
  ASSERT_TRUE(f.write("abc", 3).ok());
  EXPECT_TRUE(names().empty()) << "an unnamed temporary: " << testing::PrintToString(names());
  EXPECT_TRUE(f.temp_path().empty());
  ASSERT_TRUE(f.commit().ok());
  EXPECT_EQ(names(), std::vector<std::string>{"out.csv"});
  EXPECT_EQ(read(path("out.csv")), "abc");
}

TEST_F(AtomicFileTest, AWriterKilledMidWriteLeavesNothing) {
  write_text(path("out.csv"), "old");
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    AtomicFile f;
    if (!f.open(path("out.csv")).ok() || !f.write("partial", 7).ok()) ::_exit(3);
    ::kill(::getpid(), SIGKILL);
    ::_exit(4);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL) << status;
  EXPECT_EQ(names(), std::vector<std::string>{"out.csv"}) << "no temporary survives SIGKILL";
  EXPECT_EQ(read(path("out.csv")), "old");
}

// An external writer of an output that is redone (Remove: a movie, a plot, a log tool's output)
// writes an unnamed file by its /proc path: nothing has a name until commit, and a writer killed
// mid-write leaves nothing.
TEST_F(AtomicFileTest, OpenExternalRemoveGivesTheWriterAnUnnamedFile) {
  AtomicFile f;
  f.open_external(path("movie.mp4"), AtomicFile::Leftovers::Remove);
  EXPECT_EQ(f.writer_path().rfind("/proc/" + std::to_string(::getpid()) + "/fd/", 0), 0u) << f.writer_path();
  write_text(f.writer_path(), "frames");
  EXPECT_TRUE(names().empty()) << "unnamed until commit";
  ASSERT_TRUE(f.commit().ok());
  EXPECT_EQ(names(), std::vector<std::string>{"movie.mp4"});
  EXPECT_EQ(read(path("movie.mp4")), "frames");

  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    AtomicFile g;
    g.open_external(path("movie.mp4"), AtomicFile::Leftovers::Remove);
    write_text(g.writer_path(), "partial");
    ::kill(::getpid(), SIGKILL);
    ::_exit(4);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL) << status;
  EXPECT_EQ(names(), std::vector<std::string>{"movie.mp4"}) << "no temporary survives SIGKILL";
  EXPECT_EQ(read(path("movie.mp4")), "frames");
}

// ulimit -f: with SIGXFSZ ignored (as rbsim's main does) the write fails with EFBIG, and the error
// names the file and the bytes written before it.
TEST_F(AtomicFileTest, AFileSizeLimitIsAnErrorNamingTheFileAndTheBytesWritten) {
  int pipe_fds[2];
  ASSERT_EQ(::pipe(pipe_fds), 0);
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    ::close(pipe_fds[0]);
    std::signal(SIGXFSZ, SIG_IGN);
    const rlimit limit{64 * 1024, 64 * 1024};
    ::setrlimit(RLIMIT_FSIZE, &limit);
    AtomicFile f;
    std::string message = "open failed";
    if (f.open(path("big.csv")).ok()) {
      const std::string block(4096, 'x');
      Status st;
      for (int i = 0; i < 64 && st.ok(); ++i) st = f.write(block.data(), block.size());
      if (st.ok()) st = f.commit();
      message = st.ok() ? "no error" : st.error().message;
    }
    const ssize_t n = ::write(pipe_fds[1], message.data(), message.size());
    ::_exit(n < 0 ? 5 : 0);
  }
  ::close(pipe_fds[1]);
  std::string message;
  char buf[512];
  for (ssize_t n; (n = ::read(pipe_fds[0], buf, sizeof buf)) > 0;)
    message.append(buf, static_cast<std::size_t>(n));
  ::close(pipe_fds[0]);
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << status;
  EXPECT_NE(message.find(path("big.csv") + ": write failed after "), std::string::npos) << message;
  EXPECT_NE(message.find(" bytes: " + std::string(std::strerror(EFBIG))), std::string::npos) << message;
  EXPECT_TRUE(names().empty()) << testing::PrintToString(names());
}

// An external writer's temporary, left by a killed process: removed at the next start for an output
// that is redone (Remove), kept for a recording that `rbsim log recover` saves (Keep).
TEST_F(AtomicFileTest, OpenExternalRemovesADeadProcesssLeftoversOnlyWhenAsked) {
  pid_t dead = 4000000;
  while (::kill(dead, 0) == 0 || errno != ESRCH) ++dead;
  const std::string left = "out.mp4.tmp." + std::to_string(dead);
  const std::string alive = "out.mp4.tmp." + std::to_string(::getppid());  // a running process's
  write_text(path(left), "partial");
  write_text(path(alive), "in use");
  write_text(path("out.mp4.tmp.notapid"), "other");
  {
    AtomicFile keep;
    keep.open_external(path("out.mp4"));
  }
  const auto sorted = [](std::vector<std::string> v) {
    std::sort(v.begin(), v.end());
    return v;
  };
  EXPECT_EQ(names(), sorted({left, alive, "out.mp4.tmp.notapid"}));
  AtomicFile f;
  f.open_external(path("out.mp4"), AtomicFile::Leftovers::Remove);
  EXPECT_EQ(names(), sorted({alive, "out.mp4.tmp.notapid"}));
}

}  // namespace
}  // namespace rbsim
