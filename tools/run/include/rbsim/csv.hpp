// The CSV outputs of a run (rbsim run --csv / --energy-csv, rbsim log export): their columns,
// their rows, and the file they are written to. One definition, so a recording exported back to
// CSV is byte for byte what the run wrote.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "rbsim/atomic_file.hpp"
#include "rbsim/core.hpp"

namespace rbsim {

// Per-body CSV: one row per body per step; `body` is its id (a scene body's index in the file, a
// spawned body's id given at its spawn, never reused).
inline constexpr char kBodyCsvColumns[] =
    "step,t,body,x,y,theta,vx,vy,omega,px,py,L_point,L_spin,T_point,T_spin";
// Scene-wide CSV: one row per step, the energies and the scene totals.
inline constexpr char kEnergyCsvColumns[] = "step,t,U,T_point,T_spin,T,E,U_gravity,U_spring,px,py,L";

// Decimal forms that read back as exactly the value written (doubles in shortest round-trip form).
void append_int(std::string& out, std::int64_t v);
void append_double(std::string& out, double v);

// One kBodyCsvColumns row (with its newline). t is World::time() of `step`.
void append_body_row(std::string& out, std::int64_t step, double t, std::int32_t body, const BodyState& state,
                     const BodyQuantities& quantities);
// One kEnergyCsvColumns row (with its newline): U, T and E are Energy's own sums of `energy`'s terms.
void append_energy_row(std::string& out, std::int64_t step, double t, const Energy& energy,
                       const SceneTotals& totals);

// A CSV file: the header line, then rows appended to rows() and handed to the file in large
// writes; written under a temporary name and renamed into place by commit() (AtomicFile).
class CsvWriter {
 public:
  [[nodiscard]] Status open(const std::string& path, std::string_view columns);
  bool is_open() const { return open_; }
  std::string& rows() { return buffer_; }
  // Writes the rows appended so far once they fill a block; call after each step's rows.
  [[nodiscard]] Status flush_if_full();
  // Writes the remaining rows and renames the file into place. A writer never opened commits
  // nothing (an output that was not asked for).
  [[nodiscard]] Status commit();

 private:
  [[nodiscard]] Status flush();
  AtomicFile file_;
  std::string buffer_;
  bool open_ = false;
};

}  // namespace rbsim
