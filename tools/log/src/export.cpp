// rbsim log export: a recording back into the CSV files `rbsim run --csv / --energy-csv` write.
//
// Bit-exactness, column by column (tools/io/src/sinks.cpp, sim_core/src/world.cpp,
// tools/msgs/src/encode.cpp):
//  - t = double(step) * dt, with step from the messages and dt from SceneDescription;
//  - x..omega from BodyStates and px..T_spin from EnergyTerms.bodies: copies of the world's values;
//  - T_point, T_spin, px, py, L: EnergyTerms totals, summed over bodies in the order the
//    energy CSV sums them;
//  - U_spring: the SPRING entries of EnergyTerms.forces summed from 0 in spring order, as
//    World::energy() does;
//  - U_gravity: World::energy() keeps one running sum over every gravity field, EnergyTerms one
//    per field. With at most one field they are the same number; with more, U_gravity is
//    recomputed from SceneDescription (masses, accelerations) and BodyStates (x, y) with
//    World::energy()'s expression (the build never contracts to FMA: -ffp-contract=off);
//  - U = U_gravity + U_spring, T = T_point + T_spin, E = U + T: Energy's own formulas (the
//    recorded potential and total associate differently, so they are not used).
#include <charconv>

#include "rbsim/export.hpp"
#include "rbsim/io.hpp"
#include "rbsim/msgs.hpp"
#include "rbsim/recording.hpp"

namespace rbsim::log {

namespace {

void append_int(std::string& out, std::int64_t v) {
  char buf[24];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, ec == std::errc() ? end : buf);
}

class CsvOut {
 public:
  Status open(const std::string& path, const char* header) {
    if (path.empty()) return Ok{};
    active_ = true;
    if (Status st = file_.open(path); !st) return st;
    buffer_ = header;
    buffer_ += '\n';
    return Ok{};
  }
  bool active() const { return active_; }
  std::string& buffer() { return buffer_; }
  Status maybe_flush() { return buffer_.size() >= (1u << 20) ? flush() : Status(Ok{}); }
  Status commit() {
    if (!active_) return Ok{};
    if (Status st = flush(); !st) return st;
    return file_.commit();
  }

 private:
  Status flush() {
    Status st = file_.write(buffer_.data(), buffer_.size());
    buffer_.clear();
    return st;
  }
  bool active_ = false;
  AtomicFile file_;
  std::string buffer_;
};

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
    if (Status st =
            csv_.open(options_.csv, "step,t,body,x,y,theta,vx,vy,omega,px,py,L_point,L_spin,T_point,T_spin");
        !st) {
      return st.error();
    }
    if (Status st =
            energy_.open(options_.energy_csv, "step,t,U,T_point,T_spin,T,E,U_gravity,U_spring,px,py,L");
        !st) {
      return st.error();
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
  // One step's rows; the reader has checked the messages against the scene description.
  Status write(const RecordedStep& d) {
    const msgs::SceneMessage& s = *scene_;
    const bool need_states = csv_.active() || (energy_.active() && s.gravity.size() > 1);
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
    if (csv_.active()) {
      std::string& out = csv_.buffer();
      for (std::size_t b = 0; b < n; ++b) {
        const BodyState& st = d.body_states->bodies[b].state;
        const msgs::EnergyTermsMessage::Body& q = en.bodies[b];
        append_int(out, step);
        out += ',';
        append_double(out, t);
        out += ',';
        append_int(out, static_cast<std::int64_t>(b));
        for (double v :
             {st.position.x(), st.position.y(), st.theta, st.velocity.x(), st.velocity.y(), st.omega,
              q.momentum.x(), q.momentum.y(), q.l_point, q.l_spin, q.t_point, q.t_spin}) {
          out += ',';
          append_double(out, v);
        }
        out += '\n';
      }
      if (Status st = csv_.maybe_flush(); !st) return st;
    }
    if (energy_.active()) {
      constexpr auto kGravity = static_cast<std::uint8_t>(msgs::EnergyTermsMessage::ForceKind::Gravity);
      double u_gravity = 0.0;
      if (s.gravity.size() == 1) {
        for (const auto& f : en.forces) {
          if (f.kind == kGravity) {
            u_gravity = f.potential;
            break;
          }
        }
      } else {
        for (const GravityDef& g : s.gravity) {
          const double ax = g.acceleration.x(), ay = g.acceleration.y();
          for (std::size_t b = 0; b < n; ++b) {
            const Vec2& x = d.body_states->bodies[b].state.position;
            u_gravity -= s.bodies[b].mass * (ax * x.x() + ay * x.y());
          }
        }
      }
      double u_spring = 0.0;
      for (const auto& f : en.forces) {
        if (f.kind != kGravity) u_spring += f.potential;
      }
      Energy e;
      e.u_gravity = u_gravity;
      e.u_spring = u_spring;
      e.t_point = en.kinetic_point;
      e.t_spin = en.kinetic_spin;
      std::string& out = energy_.buffer();
      append_int(out, step);
      for (double v : {t, e.potential(), e.t_point, e.t_spin, e.kinetic(), e.total(), e.u_gravity, e.u_spring,
                       en.momentum.x(), en.momentum.y(), en.angular_momentum}) {
        out += ',';
        append_double(out, v);
      }
      out += '\n';
      if (Status st = energy_.maybe_flush(); !st) return st;
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
  CsvOut csv_, energy_;
};

}  // namespace

Result<ExportReport> export_csv(const std::string& path, const ExportOptions& options) {
  return Exporter(path, options).run();
}

}  // namespace rbsim::log
