// rbsim log export: a recording back into the CSV files `rbsim run --csv / --energy-csv` write.
//
// Bit-exactness, column by column (rows by tools/run/src/csv.cpp as for `rbsim run`; values from
// sim_core/src/world.cpp through tools/msgs/src/encode.cpp):
//  - t = double(step) * dt, with step from the messages and dt from SceneDescription;
//  - x..omega from BodyStates and px..T_spin from EnergyTerms.bodies: copies of the world's values;
//  - T_point, T_spin, px, py, L: EnergyTerms totals, World::energy() and World::totals(), which
//    the energy CSV prints too;
//  - U_gravity, U_spring: EnergyTerms.potential_gravity / potential_spring, World::energy()'s.
//    Recordings made before those fields existed: U_spring is the SPRING entries of
//    EnergyTerms.forces summed from 0 in spring order, as World::energy() does; U_gravity, where
//    World::energy() keeps one running sum over every gravity field and EnergyTerms one per field,
//    is the one field's entry, or with several recomputed from SceneDescription (masses,
//    accelerations) and BodyStates (x, y) with World::energy()'s expression (bit-exact only
//    because the build never contracts to FMA: -ffp-contract=off);
//  - U = U_gravity + U_spring, T = T_point + T_spin, E = U + T: Energy's own formulas (the
//    recorded potential and total associate differently, so they are not used).
#include "rbsim/export.hpp"
#include "rbsim/csv.hpp"
#include "rbsim/msgs.hpp"
#include "rbsim/recording.hpp"

namespace rbsim::recordings {

// The energies of a recorded step as World::energy() holds them (see the bit-exactness notes at
// the top of this file).
Energy recorded_energy(const msgs::SceneMessage& s, const msgs::EnergyTermsMessage& en,
                       const msgs::BodyStatesMessage* body_states) {
  constexpr auto kGravity = static_cast<std::uint8_t>(msgs::EnergyTermsMessage::ForceKind::Gravity);
  double u_gravity = 0.0;
  if (en.has_split) {
    u_gravity = en.potential_gravity;
  } else if (s.gravity.size() == 1) {
    for (const auto& f : en.forces) {
      if (f.kind == kGravity) {
        u_gravity = f.potential;
        break;
      }
    }
  } else if (body_states != nullptr) {
    for (const GravityDef& g : s.gravity) {
      const double ax = g.acceleration.x(), ay = g.acceleration.y();
      for (std::size_t b = 0; b < s.bodies.size(); ++b) {
        const Vec2& x = body_states->bodies[b].state.position;
        u_gravity -= s.bodies[b].mass * (ax * x.x() + ay * x.y());
      }
    }
  }
  double u_spring = en.potential_spring;
  if (!en.has_split) {
    for (const auto& f : en.forces) {
      if (f.kind != kGravity) u_spring += f.potential;
    }
  }
  Energy e;
  e.u_gravity = u_gravity;
  e.u_spring = u_spring;
  e.t_point = en.kinetic_point;
  e.t_spin = en.kinetic_spin;
  return e;
}

bool recorded_energy_needs_states(const msgs::SceneMessage& s, const msgs::EnergyTermsMessage& en) {
  return !en.has_split && s.gravity.size() > 1;
}

namespace {

class Exporter {
 public:
  Exporter(std::string path, const ExportOptions& options) : path_(std::move(path)), options_(options) {}

  Result<ExportReport> run() {
    if (options_.csv.empty() && options_.energy_csv.empty()) {
      return Error{"nothing to export: give --csv and/or --energy-csv"};
    }
    RecordingOptions ro;
    ro.ns = options_.ns;
    ro.verify_crc = true;
    ro.read = {msgs::TopicId::BodyStates, msgs::TopicId::Energy};
    if (!options_.csv.empty()) ro.require.push_back(msgs::TopicId::BodyStates);
    ro.require.push_back(msgs::TopicId::Energy);
    auto recording = Recording::open(path_, ro);
    if (!recording) return recording.error();
    scene_ = recording.value()->scene();
    if (!options_.csv.empty()) {
      if (Status st = csv_.open(options_.csv, kBodyCsvColumns); !st) return st.error();
    }
    if (!options_.energy_csv.empty()) {
      if (Status st = energy_.open(options_.energy_csv, kEnergyCsvColumns); !st) return st.error();
    }
    if (Status st = recording.value()->read_steps([&](const RecordedStep& d) { return write(d); }); !st) {
      return st.error();
    }
    if (report_.steps == 0) return Error{path_ + ": no complete step in the recording"};
    if (Status st = csv_.commit(); !st) return st.error();
    if (Status st = energy_.commit(); !st) return st.error();
    return report_;
  }

 private:
  // One step's rows; the reader has checked the messages against the step's scene description. A
  // row's body is the body's id (its index until bodies come or go), as the CSV sink writes it.
  Status write(const RecordedStep& d) {
    const msgs::SceneMessage& s = d.scene != nullptr ? *d.scene : *scene_;
    const bool need_states = csv_.is_open() || (energy_.is_open() && d.energy != nullptr &&
                                                recorded_energy_needs_states(s, *d.energy));
    if ((need_states && d.body_states == nullptr) || d.energy == nullptr) {
      report_.warnings.push_back("step " + std::to_string(d.step) + ": no " +
                                 std::string(d.energy != nullptr ? "BodyStates" : "EnergyTerms") +
                                 " message (recording cut short?): step skipped");
      return Ok{};
    }
    const msgs::EnergyTermsMessage& en = *d.energy;
    const std::size_t n = s.bodies.size();
    const auto step = static_cast<std::int64_t>(d.step);
    const double t = static_cast<double>(step) * s.dt;  // World::time()
    if (csv_.is_open()) {
      for (std::size_t b = 0; b < n; ++b) {
        const msgs::EnergyTermsMessage::Body& q = en.bodies[b];
        const BodyQuantities quantities{q.momentum, q.l_point, q.l_spin, q.t_point, q.t_spin};
        const msgs::BodyStatesMessage::Body& body = d.body_states->bodies[b];
        append_body_row(csv_.rows(), step, t, body.id, body.state, quantities);
      }
      if (Status st = csv_.flush_if_full(); !st) return st;
    }
    if (energy_.is_open()) {
      const Energy e = recorded_energy(s, en, d.body_states);
      append_energy_row(energy_.rows(), step, t, e, SceneTotals{en.momentum, en.angular_momentum});
      if (Status st = energy_.flush_if_full(); !st) return st;
    }
    if (report_.steps == 0) report_.first_step = d.step;
    report_.last_step = d.step;
    ++report_.steps;
    return Ok{};
  }

  std::string path_;
  ExportOptions options_;
  ExportReport report_;
  const msgs::SceneMessage* scene_ = nullptr;
  CsvWriter csv_, energy_;
};

}  // namespace

Result<ExportReport> export_csv(const std::string& path, const ExportOptions& options) {
  return Exporter(path, options).run();
}

}  // namespace rbsim::recordings
