// Outputs of a run (the Sink boundary that CSV, FOSSSim binary, MCAP and DDS outputs implement),
// atomic output files, and the FOSSSim reference format with the reference's grading rule.
#pragma once

#include <cstdint>
#include <cstdio>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "rbsim/core.hpp"
#include "rbsim/scene.hpp"

namespace rbsim {

// A file written under a temporary name beside its final path and renamed into place by
// commit(), so readers never see a half-written output. Destroying an uncommitted AtomicFile
// removes the temporary.
class AtomicFile {
 public:
  AtomicFile() = default;
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;
  ~AtomicFile();

  [[nodiscard]] Status open(const std::string& path);
  [[nodiscard]] Status write(const void* data, std::size_t size);
  [[nodiscard]] Status commit();  // flush, fsync, rename over `path`
  void discard();
  const std::string& path() const { return path_; }
  std::uint64_t bytes_written() const { return bytes_; }

 private:
  std::string path_, temp_path_;
  std::FILE* file_ = nullptr;
  std::uint64_t bytes_ = 0;
};

// Receives the world after step 0 (begin) and after every later step the runner chooses.
class Sink {
 public:
  virtual ~Sink() = default;
  [[nodiscard]] virtual Status begin(const Scene& scene, const World& world) = 0;
  [[nodiscard]] virtual Status write(const World& world) = 0;
  // Completes the output (called after the last step, also after an interruption: whatever was
  // written stays a valid file).
  [[nodiscard]] virtual Status finish() = 0;
};

// One row per body per step, columns kBodyCsvColumns (rbsim/csv.hpp), every value printed in
// shortest round-trip form (reads back bit-exact).
std::unique_ptr<Sink> make_csv_sink(std::string path);
// One row per step, columns kEnergyCsvColumns: energies and scene totals.
std::unique_ptr<Sink> make_energy_csv_sink(std::string path);
// The FOSSSim reference binary format (see test/data/fosssim/README.md).
std::unique_ptr<Sink> make_fosssim_sink(std::string path);

// ---------------------------------------------------------------------------------------------
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
