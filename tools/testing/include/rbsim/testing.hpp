// Golden-log checks in a GoogleTest suite: record a scene in process, compare a recording with a
// golden one, and refresh goldens on request. Link rbsim::testing (find_package(rbsim)).
//
//   TEST(MyController, MatchesGolden) {
//     ASSERT_TRUE(rbsim::testing::RecordScene("scene.xml", "run.mcap", {.steps = 500, .overwrite = true}));
//     EXPECT_TRUE(rbsim::testing::UpdateGoldenIfRequested("scene.xml", "run.mcap", "golden.mcap"));
//   }
//
// A failed check's message is the report `rbsim check` prints (first divergence with topic,
// step, field, expected, actual and difference; the per-field max-error table).
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace rbsim::testing {

struct RecordOptions {
  std::optional<std::int64_t> steps{};  // steps to run; default: the scene's duration
  std::optional<double> duration{};     // simulated seconds, ceil(T / dt) steps (steps wins)
  std::int64_t record_every = 1;        // record every k-th step (step 0 always)
  std::vector<std::string> topics{};    // e.g. {"body_states", "energy"}; empty: the default set
  std::string ns = "rbsim";             // ROS namespace of the topics
  bool overwrite = false;               // replace an existing output file
  // Commands applied at step boundaries, as `rbsim run --commands`: a YAML script
  // (- {step: 500, set: {forces.0.fy: -3.7}}, impulses, pauses; see the README) or a recording of a
  // steered session (.mcap, its /<ns>/commands). Empty: none.
  std::string commands{};
};

// Runs a scene in process and writes the MCAP `rbsim run SCENE --record OUT` writes with the same
// options (bit-identical). Fails with the reason (scene error, existing output, I/O error,
// divergence of the run) in the message.
::testing::AssertionResult RecordScene(const std::string& scene_path, const std::string& out_mcap,
                                       const RecordOptions& options = {});

struct Tolerance {
  double atol = 0.0;                  // a float matches when |actual - expected| <= atol + rtol |expected|
  double rtol = 0.0;                  // both 0: bit-exact
  std::vector<std::string> topics{};  // compare only these ("body_states", "/rbsim/energy"); empty: all
};

// Compares a recording with a golden one as `rbsim check` does. Success on a match; on a
// divergence the message is `rbsim check`'s report; an unreadable input (missing, not MCAP,
// truncated) or a golden of another scene fails with one line saying so.
::testing::AssertionResult CheckLogs(const std::string& actual_mcap, const std::string& golden_mcap,
                                     const Tolerance& tolerance = {});

// The environment variable that turns golden checks into golden updates.
inline constexpr const char* kUpdateGoldensVariable = "RBSIM_UPDATE_GOLDENS";
// True when RBSIM_UPDATE_GOLDENS is set to 1.
bool GoldenUpdateRequested();

// Snapshot testing: without RBSIM_UPDATE_GOLDENS=1, CheckLogs(actual, golden, tolerance) (a
// missing golden fails, saying how to create it). With it, verifies `actual_mcap` as a golden of
// `scene_path` independently of the simulator (`rbsim check --verify-golden`) and only then
// replaces the golden with it (atomically); a recording the verifier rejects is never written.
::testing::AssertionResult UpdateGoldenIfRequested(const std::string& scene_path,
                                                   const std::string& actual_mcap,
                                                   const std::string& golden_mcap,
                                                   const Tolerance& tolerance = {});

}  // namespace rbsim::testing
