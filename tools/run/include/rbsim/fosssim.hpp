// The FOSSSim reference format (test/data/fosssim/README.md) and the reference's grading rule.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "rbsim/core.hpp"
#include "rbsim/scene.hpp"

namespace rbsim {

// FOSSSim reference output: raw little-endian doubles, per step the state then the quantities.
struct FosssimFrame {
  std::vector<BodyState> states;
  std::vector<BodyQuantities> quantities;
  double potential = 0.0;
};
struct FosssimLog {
  std::vector<double> mass, inertia;
  std::vector<Vec2> center;          // centre of mass at t = 0
  std::vector<FosssimFrame> frames;  // step 0 .. n
};

// Reads a whole file; a name ending in ".zst" is decompressed.
Result<std::vector<std::byte>> read_file(const std::string& path);
Result<FosssimLog> parse_fosssim(std::span<const std::byte> data, std::int32_t bodies);

// The reference's grading rule: at every step load the reference state, check that step's
// quantities, step once and compare with the reference's next state.
struct GradeOptions {
  double max_step_diff = 1e-8;  // largest per-step state difference (X, theta, V, omega)
  double sum_step_diff = 1e-6;  // summed over all steps
  double quantity_tol = 1e-8;   // every quantity, absolute
};
struct GradeReport {
  bool passed = false;
  std::int64_t steps = 0;
  double max_step_diff = 0.0, sum_step_diff = 0.0, max_quantity_diff = 0.0;
  std::int64_t worst_step = 0;  // where max_step_diff occurred
  std::string worst_quantity;   // e.g. "step 12 body 0 T_spin"
  std::string message;          // why it failed (empty on success)
};
Result<GradeReport> grade(const Scene& scene, const FosssimLog& reference, const GradeOptions& options = {});

}  // namespace rbsim
