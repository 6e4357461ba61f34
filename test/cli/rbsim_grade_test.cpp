// `rbsim grade`: PASS against a matching reference, FAIL when the scene is perturbed.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "rbsim/subprocess.hpp"

namespace rbsim {
namespace {

namespace fs = std::filesystem;
using test::rbsim;
using test::read_text;
using test::TempDir;

const std::string kScenes = std::string(RBSIM_TEST_DATA_DIR) + "/fosssim/scenes";
const std::string kReference = RBSIM_FOSSSIM_REFERENCE_DIR;

std::string describe(const test::Outcome& o) {
  return "exit " + std::to_string(o.exit_code) + (o.timed_out ? " (timed out)" : "") + "\nstdout: " + o.out +
         "\nstderr: " + o.err;
}

// Copies `scene` into `dir` with the first `from` replaced by `to`.
std::string perturbed(const TempDir& dir, const std::string& scene, const std::string& from,
                      const std::string& to) {
  std::string text = read_text(scene);
  const auto at = text.find(from);
  if (at == std::string::npos) throw std::runtime_error(from + " not in " + scene);
  text.replace(at, from.size(), to);
  const fs::path out = dir / fs::path(scene).filename().string();
  test::write_text(out, text);
  return out.string();
}

// A reference written by rbsim itself (--fosssim-out) grades as PASS with zero differences.
TEST(RbsimGrade, PassesAgainstItsOwnFosssimOutput) {
  TempDir dir;
  for (const char* name :
       {"/springtests/test02sym.xml", "/windtests/test03ee.xml", "/gravitytests/test01sym.xml"}) {
    const std::string scene = kScenes + name, ref = (dir / "ref.bin").string();
    const test::Outcome run = rbsim({"run", scene, "-q", "--overwrite", "--fosssim-out", ref});
    ASSERT_EQ(run.exit_code, 0) << describe(run);
    const test::Outcome g = rbsim({"grade", scene, ref});
    EXPECT_EQ(g.exit_code, 0) << name << "\n" << describe(g);
    EXPECT_NE(g.out.find(": PASS"), std::string::npos) << g.out;
    EXPECT_NE(g.out.find("max step diff 0 "), std::string::npos) << g.out;
  }
}

// dt 0.01 -> 0.0100001 keeps ceil(duration / dt) (so the reference still has the right number of
// frames) but changes every step by ~1e-7: FAIL, exit 1.
TEST(RbsimGrade, FailsWhenDtIsPerturbed) {
  TempDir dir;
  const std::string scene = kScenes + "/gravitytests/test00ee.xml", ref = (dir / "ref.bin").string();
  ASSERT_EQ(rbsim({"run", scene, "-q", "--fosssim-out", ref}).exit_code, 0);
  const std::string bad = perturbed(dir, scene, "dt=\"0.01\"", "dt=\"0.0100001\"");
  const test::Outcome g = rbsim({"grade", bad, ref});
  EXPECT_EQ(g.exit_code, 1) << describe(g);
  EXPECT_NE(g.out.find(": FAIL"), std::string::npos) << g.out;
  EXPECT_NE(g.out.find("state differs"), std::string::npos) << g.out;
}

TEST(RbsimGrade, FailsWhenAMassIsPerturbed) {
  TempDir dir;
  const std::string scene = kScenes + "/springtests/test02sym.xml", ref = (dir / "ref.bin").string();
  ASSERT_EQ(rbsim({"run", scene, "-q", "--fosssim-out", ref}).exit_code, 0);
  const std::string bad = perturbed(dir, scene, "m=\"1\"", "m=\"1.001\"");
  const test::Outcome g = rbsim({"grade", bad, ref});
  EXPECT_EQ(g.exit_code, 1) << describe(g);
  EXPECT_NE(g.out.find(": FAIL"), std::string::npos) << g.out;
}

// A reference with the wrong number of frames cannot be graded at all: an error, exit 2.
TEST(RbsimGrade, MismatchedReferenceIsAnError) {
  TempDir dir;
  const std::string scene = kScenes + "/gravitytests/test00ee.xml", ref = (dir / "ref.bin").string();
  ASSERT_EQ(rbsim({"run", scene, "-q", "--steps", "10", "--fosssim-out", ref}).exit_code, 0);
  const test::Outcome g = rbsim({"grade", scene, ref});
  EXPECT_EQ(g.exit_code, 2) << describe(g);
  EXPECT_NE(g.err.find("frames"), std::string::npos) << g.err;
  // a reference for another body count
  const test::Outcome other = rbsim({"grade", kScenes + "/windtests/test00ee.xml", ref});
  EXPECT_EQ(other.exit_code, 2) << describe(other);
  // missing files
  const test::Outcome missing = rbsim({"grade", scene, (dir / "nope.bin").string()});
  EXPECT_EQ(missing.exit_code, 2) << describe(missing);
  EXPECT_NE(missing.err.find("nope.bin"), std::string::npos) << missing.err;
  const test::Outcome no_scene = rbsim({"grade", (dir / "nope.xml").string(), ref});
  EXPECT_EQ(no_scene.exit_code, 2) << describe(no_scene);
  EXPECT_NE(no_scene.err.find("nope.xml"), std::string::npos) << no_scene.err;
}

TEST(RbsimGrade, HelpExitsZero) {
  const test::Outcome o = rbsim({"grade", "--help"});
  EXPECT_EQ(o.exit_code, 0) << describe(o);
  EXPECT_NE(o.out.find("reference"), std::string::npos);
}

// Against the FOSSSim reference solver's own output, kept in the repository (test/data/fosssim):
// a missing reference file is a broken path, so the test fails rather than skips.
class RbsimGradeFosssim : public ::testing::TestWithParam<const char*> {};

TEST_P(RbsimGradeFosssim, PassesAndFailsWhenPerturbed) {
  const std::string name = GetParam();
  const std::string ref = kReference + "/" + name + ".bin.zst";
  ASSERT_TRUE(fs::exists(ref)) << "no FOSSSim reference at " << ref << " (RBSIM_FOSSSIM_REFERENCE_DIR)";
  const std::string scene = kScenes + "/" + name + ".xml";
  const test::Outcome g = rbsim({"grade", scene, ref}, std::chrono::seconds(120));
  EXPECT_EQ(g.exit_code, 0) << describe(g);
  EXPECT_NE(g.out.find(": PASS"), std::string::npos) << g.out;

  TempDir dir;
  const std::string bad = perturbed(dir, scene, "dt=\"0.01\"", "dt=\"0.0100001\"");
  const test::Outcome f = rbsim({"grade", bad, ref}, std::chrono::seconds(120));
  EXPECT_EQ(f.exit_code, 1) << describe(f);
  EXPECT_NE(f.out.find(": FAIL"), std::string::npos) << f.out;
}

INSTANTIATE_TEST_SUITE_P(PublicScenes, RbsimGradeFosssim,
                         ::testing::Values("gravitytests/test00ee", "springtests/test02sym",
                                           "windtests/test03ee", "inertiatests/test02sym"),
                         [](const auto& tp) {
                           std::string n = tp.param;
                           for (char& c : n) c = c == '/' ? '_' : c;
                           return n;
                         });

}  // namespace
}  // namespace rbsim
