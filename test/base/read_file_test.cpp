// read_whole_file / read_text_file: every byte back (NULs, no newline translation), and errors
// that name the path, what it was and why.
#include "rbsim/read_file.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace rbsim {
namespace {

namespace fs = std::filesystem;

class ReadFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("rbsim_read_file_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string write(const std::string& name, const std::string& content) const {
    const std::string p = (dir_ / name).string();
    std::ofstream(p, std::ios::binary) << content;
    return p;
  }
  fs::path dir_;
};

TEST_F(ReadFileTest, ReadWholeFileReturnsEveryByte) {
  std::string content;
  for (int i = 0; i < 3000; ++i) content.push_back(static_cast<char>((i * 7) % 256));  // NULs, \r, \n
  const Result<Bytes> got = read_whole_file(write("binary.bin", content));
  ASSERT_TRUE(got) << got.error().message;
  ASSERT_EQ(got->size(), content.size());
  for (std::size_t i = 0; i < content.size(); ++i)
    ASSERT_EQ(std::to_integer<unsigned char>((*got)[i]), static_cast<unsigned char>(content[i])) << i;
}

TEST_F(ReadFileTest, ReadTextFileOfAnEmptyFileIsEmpty) {
  const Result<std::string> got = read_text_file(write("empty.xml", ""));
  ASSERT_TRUE(got) << got.error().message;
  EXPECT_TRUE(got->empty());
  const Result<std::string> text = read_text_file(write("scene.xml", "<scene>\r\n</scene>"));
  ASSERT_TRUE(text);
  EXPECT_EQ(*text, "<scene>\r\n</scene>");
}

TEST_F(ReadFileTest, ReadWholeFileOfAMissingFileNamesPathWhatAndReason) {
  const std::string missing = (dir_ / "nope.xml").string();
  const Result<std::string> got = read_text_file(missing, "scene file");
  ASSERT_FALSE(got);
  EXPECT_EQ(got.error().code, ErrorCode::IoError);
  EXPECT_EQ(got.error().message, missing + ": cannot open scene file: No such file or directory");
  const Result<Bytes> bare = read_whole_file(missing);
  ASSERT_FALSE(bare);
  EXPECT_EQ(bare.error().message, missing + ": cannot open: No such file or directory");
}

TEST_F(ReadFileTest, ReadWholeFileOfADirectoryIsAnError) {
  const Result<Bytes> got = read_whole_file(dir_.string());
  ASSERT_FALSE(got);
  EXPECT_EQ(got.error().message, dir_.string() + ": is a directory");
}

}  // namespace
}  // namespace rbsim
