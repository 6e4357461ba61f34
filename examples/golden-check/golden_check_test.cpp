// The golden-log check a project writes for its own scene: record it, compare with the golden.
#include <rbsim/testing.hpp>

namespace {

const std::string kScene = EXAMPLE_DIR "/pendulum.xml";
const std::string kGolden = EXAMPLE_DIR "/golden/pendulum.mcap";

TEST(Pendulum, MatchesGolden) {
  const std::string run = OUTPUT_DIR "/pendulum.mcap";
  ASSERT_TRUE(rbsim::testing::RecordScene(kScene, run, {.overwrite = true}));
  EXPECT_TRUE(rbsim::testing::UpdateGoldenIfRequested(kScene, run, kGolden));
}

TEST(Pendulum, ShorterRunIsReported) {
  if (rbsim::testing::GoldenUpdateRequested()) GTEST_SKIP() << "updating goldens";
  const std::string run = OUTPUT_DIR "/pendulum-short.mcap";
  ASSERT_TRUE(rbsim::testing::RecordScene(kScene, run, {.steps = 100, .overwrite = true}));
  const ::testing::AssertionResult check = rbsim::testing::CheckLogs(run, kGolden);
  ASSERT_FALSE(check);
  // The failure explains itself: rbsim check's report, naming the steps the run lacks.
  EXPECT_NE(std::string(check.message()).find("run lacks steps 101..200"), std::string::npos)
      << check.message();
}

}  // namespace
