// rbsim log export: a recording back into the CSV files `rbsim run --csv / --energy-csv` write.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "rbsim/core.hpp"
#include "rbsim/msgs.hpp"

namespace rbsim::recordings {

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

// A recorded step's energies exactly as World::energy() held them, so U, T and E by Energy's own
// formulas are the energy CSV's (the message's own potential and total associate differently).
// A recording made before the potential split, of a scene with several gravity fields, needs the
// step's body states for U_gravity (recorded_energy_needs_states; without them U_gravity is 0).
Energy recorded_energy(const msgs::SceneMessage& scene, const msgs::EnergyTermsMessage& energy,
                       const msgs::BodyStatesMessage* body_states);
bool recorded_energy_needs_states(const msgs::SceneMessage& scene, const msgs::EnergyTermsMessage& energy);

}  // namespace rbsim::recordings
