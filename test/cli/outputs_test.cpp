// Output paths as a new user meets them: every command checks its outputs before any work
// starts, refuses to replace an existing file unless --overwrite, never writes over an input,
// and never gives two outputs one file.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "rbsim/subprocess.hpp"

namespace rbsim {
namespace {

namespace fs = std::filesystem;
using test::rbsim;

const std::string kScene = std::string(RBSIM_TEST_DATA_DIR) + "/fosssim/scenes/springtests/test02sym.xml";

// A copy of a scene the test may lose, and a recording of it.
struct Fixture {
  test::TempDir dir;
  fs::path scene = dir / "scene.xml", log = dir / "run.mcap";
  Fixture() {
    test::write_text(scene, test::read_text(kScene));
    const test::Outcome o = rbsim({"run", scene.string(), "-q", "--steps", "20", "--record", log.string()});
    EXPECT_EQ(o.exit_code, 0) << o;
  }
};

TEST(RunOutputs, AnExistingOutputIsRefusedBeforeStepZeroUnlessOverwrite) {
  Fixture f;
  const fs::path csv = f.dir / "good.csv";
  test::write_text(csv, "a good CSV\n");
  // A long run: refused at once, before any step (the timeout would catch a run to the end).
  const test::Outcome o = rbsim({"run", f.scene.string(), "--steps", "100000000", "--csv", csv.string()},
                                std::chrono::seconds(20));
  EXPECT_EQ(o.exit_code, 1) << o;
  EXPECT_NE(o.err.find("--csv " + csv.string() + ": exists (use --overwrite to replace it)"),
            std::string::npos)
      << o;
  EXPECT_EQ(test::read_text(csv), "a good CSV\n");
  const test::Outcome ok =
      rbsim({"run", f.scene.string(), "-q", "--steps", "3", "--csv", csv.string(), "--overwrite"});
  EXPECT_EQ(ok.exit_code, 0) << ok;
  EXPECT_EQ(test::lines_of(test::read_text(csv)).size(), 1u + 4u * 2u);  // header, 2 bodies x steps 0..3
}

TEST(RunOutputs, TheSceneIsNeverWrittenOverEvenWithOverwrite) {
  Fixture f;
  const std::string before = test::read_text(f.scene);
  for (const char* option : {"--csv", "--energy-csv", "--fosssim-out", "--record"}) {
    const test::Outcome o = rbsim({"run", f.scene.string(), "--overwrite", option, f.scene.string()});
    EXPECT_EQ(o.exit_code, 1) << option << o;
    EXPECT_NE(o.err.find("is an input of this command; refusing to write over it"), std::string::npos) << o;
  }
  EXPECT_EQ(test::read_text(f.scene), before);
}

TEST(RunOutputs, BadPathsAreFoundBeforeTheRun) {
  Fixture f;
  fs::create_directories(f.dir / "folder");
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
      {{"--csv", (f.dir / "folder").string()}, "is a folder (give a file name)"},
      {{"--csv", (f.dir / "same.csv").string(), "--energy-csv", (f.dir / "same.csv").string()},
       "is also the output of --csv"},
      {{"--record", (f.dir / "missing" / "r.mcap").string()}, "does not exist"},
      {{"--frames", f.log.string()}, "exists and is not a folder"},
  };
  for (const auto& [args, rule] : cases) {
    std::vector<std::string> all = {"run", f.scene.string(), "--steps", "100000000"};
    all.insert(all.end(), args.begin(), args.end());
    const test::Outcome o = rbsim(all, std::chrono::seconds(20));
    EXPECT_EQ(o.exit_code, 1) << o;
    EXPECT_NE(o.err.find(rule), std::string::npos) << o;
  }
  EXPECT_FALSE(fs::exists(f.dir / "same.csv"));
}

TEST(PlotOutputs, RefusesAnExistingPngAndDurationOnARecording) {
  Fixture f;
  const fs::path png = f.dir / "plot.png";
  test::write_text(png, "not yours");
  const test::Outcome o = rbsim({"plot", f.scene.string(), "--out", png.string()});
  EXPECT_EQ(o.exit_code, 1) << o;
  EXPECT_NE(o.err.find("exists (use --overwrite"), std::string::npos) << o;
  EXPECT_EQ(test::read_text(png), "not yours");
  const test::Outcome d =
      rbsim({"plot", f.log.string(), "--out", (f.dir / "p2.png").string(), "--duration", "1"});
  EXPECT_EQ(d.exit_code, 2) << d;
  EXPECT_NE(d.err.find("--duration applies to a scene, not to a recording"), std::string::npos) << d;
}

TEST(LogOutputs, ExportAndRecoverRefuseExistingOutputsAndTheirInput) {
  Fixture f;
  const fs::path csv = f.dir / "e.csv";
  test::write_text(csv, "keep");
  const test::Outcome e = rbsim({"log", "export", f.log.string(), "--csv", csv.string()});
  EXPECT_EQ(e.exit_code, 1) << e;
  EXPECT_NE(e.err.find("exists (use --overwrite"), std::string::npos) << e;
  EXPECT_EQ(test::read_text(csv), "keep");
  const test::Outcome e2 = rbsim({"log", "export", f.log.string(), "--csv", f.log.string(), "--overwrite"});
  EXPECT_EQ(e2.exit_code, 1) << e2;
  EXPECT_NE(e2.err.find("is an input"), std::string::npos) << e2;
  const test::Outcome r = rbsim({"log", "recover", f.log.string(), csv.string()});
  EXPECT_EQ(r.exit_code, 1) << r;
  EXPECT_EQ(test::read_text(csv), "keep");
  const test::Outcome r2 = rbsim({"log", "recover", f.log.string(), csv.string(), "--overwrite", "-q"});
  EXPECT_EQ(r2.exit_code, 0) << r2;
}

}  // namespace
}  // namespace rbsim

namespace rbsim {
namespace {

// ulimit -f: the run stops with one line naming the output and the bytes that reached it, exit 1,
// and leaves nothing behind (its CSV was an unnamed file until commit).
TEST(RunOutputs, AFileSizeLimitStopsTheRunNamingTheFileAndTheBytes) {
  test::TempDir dir;
  const std::string csv = (dir / "big.csv").string();
  const std::string scene = std::string(RBSIM_TEST_DATA_DIR) + "/../../scenes/cantilever.xml";
  const test::Outcome o = test::run_process(
      "/bin/sh",
      {"-c", "ulimit -f 128 && exec \"$0\" run \"$1\" --steps 3000 --csv \"$2\" -q", RBSIM_EXE, scene, csv});
  EXPECT_EQ(o.exit_code, 1) << o;
  EXPECT_NE(o.err.find("rbsim run: error: " + csv + ": write failed after "), std::string::npos) << o;
  EXPECT_NE(o.err.find(" bytes: File too large"), std::string::npos) << o;
  EXPECT_EQ(test::lines_of(o.err).size(), 1u) << o;
  std::vector<std::string> left;
  for (const auto& e : fs::directory_iterator(dir.path())) left.push_back(e.path().filename().string());
  EXPECT_TRUE(left.empty()) << testing::PrintToString(left);
}

}  // namespace
}  // namespace rbsim
