// The golden verifier's stages, in the order verify_golden runs them (golden.cpp). Each checks
// the messages it is handed against the scene and the verifier's own physics (physics.hpp) and
// adds its PASS / FAIL / info lines to the report.
#pragma once

#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "golden_log.hpp"
#include "physics.hpp"
#include "rbsim/golden.hpp"
#include "rbsim/scene.hpp"
#include "tally.hpp"

namespace rbsim::check {

// What every stage reads.
struct StageContext {
  const Scene& scene;
  const Model& model;
  const GoldenVerifyOptions& options;
  Report& report;
  GoldenVerification& verification() const { return report.verification; }
};

// The recorded steps and the body states at each, once the recording's steps have passed.
struct RecordedRun {
  std::vector<std::uint64_t> steps;
  std::vector<State> states;
  std::vector<Terms> terms;  // recomputed from each state
};

// The prefix of the body frames, "<namespace>/" (empty for none): the namespace of the
// body-state topic `states_topic`. Body b's frame is prefix + "body_<b>".
std::string body_frame_prefix(const std::string& states_topic);

// The recorded scene description against the scene file (M, I and hulls recomputed from the
// vertices). False when its counts differ: the recording cannot be read against this scene.
bool verify_scene_description(const StageContext& context, const LatchedScene& latched);

// The recording's steps: 0, K, 2K, ... up to the end of the run, stamped t = step * dt, the same
// steps on every per-step topic, the initial state from the scene. Sets the verification's
// record_every and last_step; the run when the checks pass.
std::optional<RecordedRun> verify_recorded_steps(const StageContext& context, const GoldenLog& log);

// The recorded energy terms, spring states, poses, /tf and springs marker of every step against
// their recomputation from the recorded body states (within recompute_rtol x max(1, |value|)).
void verify_energy_terms(const StageContext& context, const RecordedRun& run,
                         const std::vector<msgs::EnergyTermsMessage>& energy);
void verify_spring_states(const StageContext& context, const RecordedRun& run,
                          const std::vector<msgs::SpringStatesMessage>& springs);
void verify_poses(const StageContext& context, const RecordedRun& run,
                  const std::vector<msgs::PosesMessage>& poses);
void verify_tf(const StageContext& context, const RecordedRun& run, const TopicMessages<msgs::TfMessage>& tf,
               const TopicMessages<msgs::BodyStatesMessage>& states);
void verify_springs_marker(const StageContext& context, const RecordedRun& run,
                           const std::vector<msgs::MarkerMessage>& marker, const msgs::SceneMessage& desc);

// The latched markers: once at step 0, each body's hull tiled by counter-clockwise triangles and
// its closed outline in the body's frame and colour, the fixed spring anchors in world.
void verify_markers(const StageContext& context,
                    const TopicMessages<std::vector<msgs::MarkerMessage>>& markers,
                    const msgs::SceneMessage& desc, const std::string& states_topic);

// The dynamics: from each recorded state, K steps of the verifier's own integrator land on the
// next recorded state. Sets the rule "independent-integration" when they do.
void verify_integration(const StageContext& context, const RecordedRun& run);

// The golden against the FOSSSim reference output `match` names: grade() passes and the body
// states and quantities of every recorded step equal the reference's. Errors: the reference
// cannot be read.
Status verify_reference(const StageContext& context, const FosssimMatch& match, const RecordedRun& run,
                        const msgs::SceneMessage& desc, const std::vector<msgs::EnergyTermsMessage>& energy);

// Without a reference, for symplectic Euler with gravity and springs only: the total energy stays
// within its bound (rbsim/golden.hpp). Sets energy_error and energy_bound.
void verify_energy_conservation(const StageContext& context, const RecordedRun& run);

// Recorded values of one step against their recomputation, within rtol x max(1, |expected|).
class StepValues {
 public:
  StepValues(Tally& tally, double rtol, std::uint64_t step)
      : tally_(tally), rtol_(rtol), at_("step " + std::to_string(step)) {}
  static constexpr std::size_t kNoIndex = std::numeric_limits<std::size_t>::max();
  void near(double got, double want, const char* what, std::size_t index = kNoIndex);
  // Element by element; a different length is one failure.
  void each(const std::vector<double>& got, const char* path, const std::vector<double>& want);
  const std::string& at() const { return at_; }
  Tally& tally() { return tally_; }

 private:
  Tally& tally_;
  double rtol_;
  std::string at_;
};

}  // namespace rbsim::check
