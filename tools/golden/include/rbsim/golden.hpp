// Golden logs (src/golden.cpp; test/golden/README.md): the record-every rule, finding a scene's
// FOSSSim reference output, and the verification a golden log passes before it is written.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "rbsim/core.hpp"

namespace rbsim::check {

// The record-every K a golden of a scene with `steps` steps is recorded with: about 500 recorded
// steps, preferring a K that divides `steps` so the final state is in the log.
std::int64_t golden_record_every(std::int64_t steps);

// The FOSSSim public scene whose file contents equal `scene_path`'s, under
// `<fosssim_dir>/scenes/**`, and its reference output `<fosssim_dir>/reference/<group>/<name>.bin.zst`
// (empty when the reference is not there).
struct FosssimMatch {
  std::string scene;      // empty: no public scene has these contents
  std::string reference;  // empty: no reference output for it
};
FosssimMatch find_fosssim_reference(const std::string& scene_path, const std::string& fosssim_dir);

struct GoldenVerifyOptions {
  std::string fosssim_dir;        // test/data/fosssim; empty: no reference lookup
  double state_tol = 1e-9;        // golden body states vs the reference's free run (absolute)
  double quantity_tol = 1e-8;     // golden M, I, P, L, T, U vs the reference's (absolute)
  double recompute_rtol = 1e-9;   // recorded energy / spring / pose terms vs recomputed ones
  double integration_tol = 1e-9;  // K steps of the verifier's integrator vs the next recorded state
  // The recording must end at the scene's last step (its duration); false accepts any length
  // (rbsim::testing, whose users record as many steps as their test needs).
  bool whole_run = true;
};

struct GoldenVerification {
  bool passed = false;
  // The independent results it was checked against, e.g. "fosssim-reference,
  // independent-integration" or "symplectic-energy, independent-integration".
  std::string rule;
  std::vector<std::string> lines;  // "PASS ..." / "FAIL ..." per check, "info ..." notes
  std::int64_t record_every = 0, last_step = 0, steps = 0;
  double energy_error = 0.0, energy_bound = 0.0;  // symplectic-energy rule
};

// Verifies a golden log of a scene independently of the simulator (its own code throughout; of
// sim_core only the scene loader, and grade() for the reference rule): the recorded scene description against
// the scene file (M, I and hulls recomputed from the vertices), the recording's steps and stamps, every
// recorded energy, spring and pose term recomputed from the recorded body states, and the dynamics:
//  - independent-integration (every scene): from each recorded state, K steps of the verifier's
//    own integrator (forces summed as the spec states them, the wind over its sample points) land
//    on the next recorded state within integration_tol;
//  - fosssim-reference, when the scene has a FOSSSim reference output (matched by file contents):
//    rbsim's grade() passes and the golden's body states and quantities at every recorded step
//    equal the reference's within state_tol / quantity_tol;
//  - symplectic-energy, for symplectic Euler with gravity and springs only and no reference: the
//    total energy E = T + U recomputed from the recorded states stays within
//    dt * (max_n |Pi_n| + |Pi_0|) (+ rounding) of E_0, Pi being the power of the conservative
//    forces: twice the first-order backward-error estimate (dt/2) |Pi_n - Pi_0|.
Result<GoldenVerification> verify_golden(const std::string& scene_path, const std::string& golden_path,
                                         const GoldenVerifyOptions& options = {});

// The record-every K of an existing golden log (step of its second body-state message), 1 when
// it holds a single step.
Result<std::int64_t> read_record_every(const std::string& golden_path);

}  // namespace rbsim::check
