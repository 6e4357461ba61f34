// The Sink boundary: every output of a run (CSV, FOSSSim binary, MCAP, DDS, frames, Foxglove)
// implements it, and the run driver (rbsim/run.hpp) feeds it; the file sinks of tools/run.
#pragma once

#include <memory>
#include <string>

#include "rbsim/core.hpp"
#include "rbsim/scene.hpp"

namespace rbsim {

// Receives the world after step 0 (begin) and after every later step the runner chooses.
class Sink {
 public:
  virtual ~Sink() = default;
  [[nodiscard]] virtual Status begin(const Scene& scene, const World& world) = 0;
  [[nodiscard]] virtual Status write(const World& world) = 0;
  // Completes the output (called after the last step, also after an interruption: whatever was
  // written stays a valid file).
  [[nodiscard]] virtual Status finish() = 0;
  // The run's timeline changed between two steps, by a control command (rbsim/control.hpp): it
  // resumed after a pause, was reset to step 0, or its pace changed. A sink that paces to wall time
  // starts afresh from `world`'s step (node::Pacer); the others ignore it.
  virtual void rebase(const World& world) { (void)world; }
  // Bodies or springs came or went at this boundary (a spawn or delete, rbsim/control.hpp): the
  // world's dense arrays now hold `entities`' bodies and springs, in that order. A sink whose
  // output follows says so in follows_structure() and, in restructure(), writes what the changed
  // world needs before its next step; a run whose sinks do not all follow refuses such changes.
  virtual bool follows_structure() const { return false; }
  [[nodiscard]] virtual Status restructure(const World& world, const Entities& entities) {
    (void)world;
    (void)entities;
    return Error{"this output cannot follow a world whose bodies change"};
  }
};

// One row per body per step, columns kBodyCsvColumns (rbsim/csv.hpp), every value printed in
// shortest round-trip form (reads back bit-exact).
std::unique_ptr<Sink> make_csv_sink(std::string path);
// One row per step, columns kEnergyCsvColumns: energies and scene totals.
std::unique_ptr<Sink> make_energy_csv_sink(std::string path);
// The FOSSSim reference binary format (see test/data/fosssim/README.md).
std::unique_ptr<Sink> make_fosssim_sink(std::string path);

}  // namespace rbsim
