// `rbsim record` as a new user meets it: an existing output is refused unless --overwrite, and a
// recorder that receives nothing says so, exits 1 and leaves no file. (DDS on rbsim's loopback
// configuration only, on a domain no other test uses.)
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "rbsim/subprocess.hpp"

namespace rbsim {
namespace {

namespace fs = std::filesystem;
using test::rbsim;

constexpr const char* kQuietDomain = "229";

TEST(RecordCli, RefusesAnExistingOutputUnlessOverwrite) {
  test::TempDir dir;
  const fs::path precious = dir / "precious.mcap";
  test::write_text(precious, "a recording the user wants to keep");
  const test::Outcome o =
      rbsim({"record", precious.string(), "--domain", kQuietDomain, "--wall-duration", "0.2"});
  EXPECT_EQ(o.exit_code, 1) << o;
  EXPECT_NE(o.err.find("exists (use --overwrite to replace it)"), std::string::npos) << o;
  EXPECT_EQ(test::read_text(precious), "a recording the user wants to keep");
}

TEST(RecordCli, NothingReceivedIsAnErrorAndLeavesNoFile) {
  test::TempDir dir;
  const fs::path out = dir / "empty.mcap";
  const test::Outcome o = rbsim({"record", out.string(), "--domain", kQuietDomain, "--wall-duration", "0.5"});
  EXPECT_EQ(o.exit_code, 1) << o;
  EXPECT_NE(o.err.find("nothing received on domain 229"), std::string::npos) << o;
  EXPECT_FALSE(fs::exists(out));
  // With --overwrite an existing file is replaced only by a recording: nothing received keeps
  // nothing, so the old file is gone only because the user asked for it to be replaced.
  test::write_text(out, "old");
  const test::Outcome o2 =
      rbsim({"record", out.string(), "--overwrite", "--domain", kQuietDomain, "--wall-duration", "0.2"});
  EXPECT_EQ(o2.exit_code, 1) << o2;
}

TEST(RecordCli, OutputInAMissingFolderIsRefusedBeforeStarting) {
  test::TempDir dir;
  const test::Outcome o = rbsim({"record", (dir / "no" / "such" / "out.mcap").string(), "--domain",
                                 kQuietDomain, "--wall-duration", "5"});
  EXPECT_EQ(o.exit_code, 1) << o;
  EXPECT_NE(o.err.find("does not exist"), std::string::npos) << o;
  EXPECT_EQ(o.err.find("recording"), std::string::npos) << "refused before DDS started: " << o;
}

// An empty file is said to be one; `rbsim log recover` (which cannot help it) is not suggested.
TEST(ReplayCli, EmptyFileIsNamedWithoutSuggestingRecover) {
  test::TempDir dir;
  const fs::path empty = dir / "empty.mcap";
  test::write_text(empty, "");
  const test::Outcome o = rbsim({"replay", empty.string(), "--domain", kQuietDomain});
  EXPECT_EQ(o.exit_code, 1) << o;
  EXPECT_NE(o.err.find("empty file"), std::string::npos) << o;
  EXPECT_EQ(o.err.find("recover"), std::string::npos) << o;
}

TEST(RecordCli, BagOptionsAreCheckedBeforeAnythingIsMade) {
  test::TempDir dir;
  // A bad --regex is a usage error, and the bag directory it would have made is not left behind.
  const fs::path bag = dir / "bag";
  test::Outcome o =
      rbsim({"record", bag.string(), "--regex", "(", "--domain", kQuietDomain, "--wall-duration", "5"});
  EXPECT_EQ(o.exit_code, 2) << o;
  EXPECT_NE(o.err.find("--regex \"(\": not a regular expression"), std::string::npos) << o;
  EXPECT_FALSE(fs::exists(bag));
  // Splits need a bag directory, not one .mcap file.
  o = rbsim({"record", (dir / "one.mcap").string(), "--max-file-size", "100000", "--domain", kQuietDomain});
  EXPECT_EQ(o.exit_code, 2) << o;
  EXPECT_NE(o.err.find("write a bag directory"), std::string::npos) << o;
  // An existing bag is refused unless --overwrite (its metadata.yaml would be replaced).
  fs::create_directory(bag);
  test::write_text(bag / "metadata.yaml", "a bag the user wants to keep");
  o = rbsim({"record", bag.string(), "--domain", kQuietDomain, "--wall-duration", "0.2"});
  EXPECT_EQ(o.exit_code, 1) << o;
  EXPECT_NE(o.err.find("metadata.yaml: exists (use --overwrite to replace it)"), std::string::npos) << o;
  EXPECT_EQ(test::read_text(bag / "metadata.yaml"), "a bag the user wants to keep");
  // Topics that choose nothing are a usage error.
  o = rbsim({"record", (dir / "none").string(), "--topics", "clock", "--exclude-regex", ".*", "--domain",
             kQuietDomain});
  EXPECT_EQ(o.exit_code, 2) << o;
  EXPECT_NE(o.err.find("choose no topic"), std::string::npos) << o;
  EXPECT_FALSE(fs::exists(dir / "none"));
}

}  // namespace
}  // namespace rbsim
