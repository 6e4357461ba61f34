// The golden verifier's stages one by one (tools/golden/src/stages.hpp), on the chain's golden
// read once (read_golden_log) and edited in memory: each stage passes the golden as recorded and
// fails, naming the place, the one kind of damage it is there to find.
#include <gtest/gtest.h>

#include <unistd.h>
#include <filesystem>
#include <fstream>

#include "golden_log.hpp"
#include "physics.hpp"
#include "rbsim/scene.hpp"
#include "stages.hpp"

namespace {

namespace fs = std::filesystem;
using namespace rbsim;
using namespace rbsim::check;

const fs::path kChainGolden = fs::path(RBSIM_GOLDEN_DIR) / "chain.mcap";

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// A bundled scene (the chain unless a test loads another), its model and its golden, and a
// report for the stages run.
class Stages : public ::testing::Test {
 protected:
  void SetUp() override { load("chain"); }
  void load(const std::string& name) {
    Result<Scene> scene = load_scene((fs::path(RBSIM_SCENES_DIR) / (name + ".xml")).string());
    ASSERT_TRUE(scene) << scene.error().message;
    scene_ = std::move(scene.value());
    model_ = model_of(scene_);
    Result<GoldenLog> log = read_golden_log((fs::path(RBSIM_GOLDEN_DIR) / (name + ".mcap")).string());
    ASSERT_TRUE(log) << log.error().message;
    log_ = std::move(log.value());
    verification_ = GoldenVerification{};
    verification_.steps = scene_.step_count();
  }

  StageContext context() { return StageContext{scene_, model_, options_, report_}; }
  // The report's lines, one per line, to match against.
  std::string lines() const {
    std::string out;
    for (const std::string& l : verification_.lines) out += l + "\n";
    return out;
  }
  // The recorded run as verify_recorded_steps returns it, with its terms, for the later stages.
  RecordedRun run() {
    std::optional<RecordedRun> r = verify_recorded_steps(context(), log_);
    EXPECT_TRUE(r) << lines();
    if (!r) return {};
    for (const State& s : r->states) r->terms.push_back(terms_of(model_, s));
    verification_.lines.clear();
    report_.failed = false;
    return *r;
  }

  Scene scene_;
  Model model_;
  GoldenLog log_;
  GoldenVerifyOptions options_;
  GoldenVerification verification_;
  Report report_{verification_};
};

TEST_F(Stages, ReadGoldenLogReadsEveryTopicOnce) {
  const std::size_t steps = log_.states.messages.size();
  ASSERT_GE(steps, 2u);
  EXPECT_EQ(log_.scene.messages, 1u);
  ASSERT_TRUE(log_.scene.description);
  EXPECT_EQ(log_.scene.description->bodies.size(), scene_.world.bodies.size());
  // One message per recorded step on every per-step topic, the same steps.
  const std::uint64_t every = log_.states.messages[1].step - log_.states.messages[0].step;
  EXPECT_EQ(static_cast<std::int64_t>(log_.states.messages.back().step), scene_.step_count());
  EXPECT_EQ(steps, static_cast<std::size_t>(scene_.step_count()) / every + 1);
  EXPECT_EQ(log_.springs.messages.size(), steps);
  EXPECT_EQ(log_.energy.messages.size(), steps);
  EXPECT_EQ(log_.tf.messages.size(), steps);
  EXPECT_EQ(log_.springs_marker.messages.size(), steps);
  EXPECT_EQ(log_.markers.messages.size(), 1u);
  EXPECT_TRUE(log_.poses.topic.empty());  // not recorded by default
  for (std::size_t m = 0; m < steps; ++m) {
    ASSERT_EQ(log_.springs.messages[m].step, log_.states.messages[m].step) << m;
    ASSERT_EQ(log_.energy.messages[m].step, log_.states.messages[m].step) << m;
  }
}

TEST_F(Stages, ReadGoldenLogRefusesATruncatedFile) {
  const fs::path dir = fs::temp_directory_path() / ("rbsim_stages_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path cut = dir / "cut.mcap";
  {
    std::ifstream in(kChainGolden, std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::ofstream(cut, std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  }
  Result<GoldenLog> log = read_golden_log(cut.string());
  fs::remove_all(dir);
  ASSERT_FALSE(log);
  EXPECT_TRUE(contains(log.error().message, cut.string() + ": ")) << log.error().message;
}

TEST_F(Stages, VerifySceneDescriptionNamesAChangedValue) {
  EXPECT_TRUE(verify_scene_description(context(), log_.scene));
  EXPECT_FALSE(report_.failed) << lines();
  log_.scene.description->springs[1].stiffness *= 1.01;
  EXPECT_TRUE(verify_scene_description(context(), log_.scene));  // still readable against the scene
  EXPECT_TRUE(report_.failed);
  EXPECT_TRUE(contains(lines(), "FAIL scene description: ")) << lines();
  EXPECT_TRUE(contains(lines(), "first spring 1 stiffness")) << lines();
}

TEST_F(Stages, VerifySceneDescriptionStopsOnOtherCounts) {
  log_.scene.description->bodies.pop_back();
  EXPECT_FALSE(verify_scene_description(context(), log_.scene));
  EXPECT_TRUE(contains(lines(), "body count")) << lines();
}

TEST_F(Stages, VerifyRecordedStepsFindsAMissingStep) {
  ASSERT_TRUE(verify_recorded_steps(context(), log_)) << lines();
  const std::uint64_t lost = log_.states.messages[3].step;
  for (auto* topic : {&log_.states}) {
    topic->messages.erase(topic->messages.begin() + 3);
    topic->log_time.erase(topic->log_time.begin() + 3);
  }
  EXPECT_FALSE(verify_recorded_steps(context(), log_));
  EXPECT_TRUE(contains(lines(), "where step " + std::to_string(lost) + " was expected")) << lines();
}

TEST_F(Stages, VerifyEnergyTermsNamesAWrongTotal) {
  const RecordedRun r = run();
  verify_energy_terms(context(), r, log_.energy.messages);
  EXPECT_FALSE(report_.failed) << lines();
  log_.energy.messages[4].total += 1e-3;
  verify_energy_terms(context(), r, log_.energy.messages);
  EXPECT_TRUE(contains(lines(), "FAIL energy terms: ")) << lines();
  EXPECT_TRUE(contains(lines(), "first step " + std::to_string(r.steps[4]) + " total")) << lines();
}

TEST_F(Stages, VerifySpringStatesNamesAWrongLength) {
  const RecordedRun r = run();
  verify_spring_states(context(), r, log_.springs.messages);
  EXPECT_FALSE(report_.failed) << lines();
  log_.springs.messages[2].springs[0].length += 1e-3;
  verify_spring_states(context(), r, log_.springs.messages);
  EXPECT_TRUE(contains(lines(), "first step " + std::to_string(r.steps[2]) + " springs[].length [0]"))
      << lines();
}

TEST_F(Stages, VerifyTfNamesAWrongFrame) {
  const RecordedRun r = run();
  verify_tf(context(), r, log_.tf, log_.states);
  EXPECT_FALSE(report_.failed) << lines();
  log_.tf.messages[1].transforms[2].child_frame_id = "elsewhere";
  verify_tf(context(), r, log_.tf, log_.states);
  EXPECT_TRUE(contains(lines(), "transforms[2]: world -> elsewhere")) << lines();
}

TEST_F(Stages, VerifyMarkersFindsAClockwiseTriangle) {
  load("airplane");  // the chain's bodies are rods: no triangles
  verify_markers(context(), log_.markers, *log_.scene.description, log_.states.topic);
  EXPECT_FALSE(report_.failed) << lines();
  std::vector<Vec2>& points = log_.markers.messages[0][0].points;  // body 0's hull triangles
  ASSERT_GE(points.size(), 3u);
  std::swap(points[1], points[2]);
  verify_markers(context(), log_.markers, *log_.scene.description, log_.states.topic);
  EXPECT_TRUE(contains(lines(), "body 0: triangle 0 is clockwise")) << lines();
}

TEST_F(Stages, VerifyIntegrationFindsAStateOffItsPath) {
  RecordedRun r = run();
  verify_integration(context(), r);
  EXPECT_FALSE(report_.failed) << lines();
  EXPECT_EQ(verification_.rule, "independent-integration");
  verification_.rule.clear();
  r.states[5].vx[1] += 1e-6;
  verify_integration(context(), r);
  EXPECT_TRUE(report_.failed);
  EXPECT_TRUE(verification_.rule.empty());
  // The damaged state is reached from step 4's (wrong) and leads to step 6's (wrong too).
  EXPECT_TRUE(contains(lines(), "first step " + std::to_string(r.steps[5]) + " body 1 vx")) << lines();
}

TEST_F(Stages, VerifyEnergyConservationBoundsTheDrift) {
  RecordedRun r = run();
  verify_energy_conservation(context(), r);
  EXPECT_FALSE(report_.failed) << lines();
  EXPECT_LE(verification_.energy_error, verification_.energy_bound);
  EXPECT_GT(verification_.energy_bound, 0.0);
  r.terms[7].total += 10 * verification_.energy_bound;
  verify_energy_conservation(context(), r);
  EXPECT_TRUE(contains(lines(), "at step " + std::to_string(r.steps[7]) + " <= ")) << lines();
  EXPECT_TRUE(report_.failed);
}

}  // namespace
