// rbsim log export: a recording back into the CSV files `rbsim run --csv / --energy-csv` write.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "rbsim/core.hpp"

namespace rbsim::log {

struct ExportOptions {
  std::string csv;         // per-body CSV (rbsim run --csv), empty: none
  std::string energy_csv;  // scene totals CSV (rbsim run --energy-csv), empty: none
  std::string ns;          // ROS namespace of the topics; empty: the only one in the file
};
struct ExportReport {
  std::uint64_t steps = 0;  // steps written
  std::uint64_t first_step = 0, last_step = 0;
  std::vector<std::string> warnings;
};
// Re-creates `rbsim run --csv / --energy-csv` output from a recording, byte for byte, for the
// recorded steps. Topics are found by type (rbsim_msgs/msg/SceneDescription, BodyStates,
// EnergyTerms); their schemas must equal this build's.
Result<ExportReport> export_csv(const std::string& path, const ExportOptions& options);

}  // namespace rbsim::log
