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
#include "rbsim/export.hpp"
#include "rbsim/csv.hpp"
#include "rbsim/mcap_tools.hpp"
#include "rbsim/msgs.hpp"

namespace rbsim::log {

namespace {

using msgs::Scalar;

// Reads the flat scalars of one decoded message in order, checking each kind.
class Cursor {
 public:
  explicit Cursor(const std::vector<Scalar>& s) : s_(s) {}
  double f64() { return take(Scalar::Kind::Float) ? s_[i_ - 1].f : 0.0; }
  std::int64_t i64() { return take(Scalar::Kind::Int) ? s_[i_ - 1].i : 0; }
  std::uint64_t u64() { return take(Scalar::Kind::UInt) ? s_[i_ - 1].u : 0; }
  std::uint64_t length() { return take(Scalar::Kind::Length) ? s_[i_ - 1].u : 0; }
  void str() { take(Scalar::Kind::String); }
  void boolean() { take(Scalar::Kind::Bool); }
  void skip_floats(std::uint64_t n) {
    for (std::uint64_t k = 0; k < n && ok_; ++k) f64();
  }
  void header() {
    i64();
    u64();
    str();
  }
  bool good() const { return ok_; }
  bool ok() const { return ok_ && i_ == s_.size(); }  // every scalar read

 private:
  bool take(Scalar::Kind kind) {
    if (!ok_ || i_ >= s_.size() || s_[i_].kind != kind) return ok_ = false;
    ++i_;
    return true;
  }
  const std::vector<Scalar>& s_;
  std::size_t i_ = 0;
  bool ok_ = true;
};

struct SceneData {
  double dt = 0.0;
  std::vector<double> mass;
  std::vector<std::pair<double, double>> gravity;
  std::uint64_t springs = 0;
};

struct StepData {
  std::uint64_t step = 0;
  bool have_states = false, have_energy = false;
  std::vector<double> states;      // x, y, theta, vx, vy, omega per body
  std::vector<double> quantities;  // px, py, l_point, l_spin, t_point, t_spin per body
  std::vector<double> gravity_u, spring_u;
  double px = 0, py = 0, l = 0, t_point = 0, t_spin = 0;
};

enum class Role { Scene, States, Energy };
constexpr std::string_view kTypes[] = {"rbsim_msgs/msg/SceneDescription", "rbsim_msgs/msg/BodyStates",
                                       "rbsim_msgs/msg/EnergyTerms"};
constexpr msgs::TopicId kTopicIds[] = {msgs::TopicId::Scene, msgs::TopicId::BodyStates,
                                       msgs::TopicId::Energy};

class Exporter {
 public:
  Exporter(std::string path, const ExportOptions& options) : path_(std::move(path)), options_(options) {}

  Result<ExportReport> run() {
    if (options_.csv.empty() && options_.energy_csv.empty()) {
      return Error{"nothing to export: give --csv and/or --energy-csv"};
    }
    if (std::string e = mcap_tools::unreadable(path_); !e.empty()) return Error{path_ + ": " + e};
    mcap::IndexedReader reader;
    if (mcap::Status s = reader.open(path_); !s.ok()) return Error{path_ + ": " + mcap_tools::read_error(s)};
    if (mcap::Status s = reader.verify_data_section_crc(); !s.ok()) {
      return Error{path_ + ": " + mcap_tools::read_error(s)};
    }
    // Channels known up front (the summary repeats them): check the topics before reading.
    mcap::ReadMessagesOptions ro;
    for (const auto& [id, channel] : reader.channels()) {
      const auto sc = reader.schemas().find(channel.schema_id);
      if (sc == reader.schemas().end()) continue;
      if (Status st = classify(channel, sc->second); !st) return st.error();
    }
    if (!reader.channels().empty()) {
      if (Status st = require_topics(); !st) return st.error();
      for (const auto& topic : topics_) {
        if (!topic.empty()) ro.topics.push_back(topic);
      }
    }
    if (!options_.csv.empty()) {
      if (Status st = csv_.open(options_.csv, kBodyCsvColumns); !st) return st.error();
    }
    if (!options_.energy_csv.empty()) {
      if (Status st = energy_.open(options_.energy_csv, kEnergyCsvColumns); !st) return st.error();
    }
    Status failure = Ok{};
    mcap::Status read = reader.read_messages(ro, [&](const mcap::MessageEntry& e) {
      failure = message(e);
      return static_cast<bool>(failure);
    });
    if (!read.ok()) return Error{path_ + ": " + mcap_tools::read_error(read)};
    if (!failure) return failure.error();
    if (Status st = require_topics(); !st) return st.error();
    if (current_) {
      if (Status st = flush(); !st) return st.error();
    }
    if (report_.steps == 0) return Error{path_ + ": no complete step in the recording"};
    if (Status st = csv_.commit(); !st) return st.error();
    if (Status st = energy_.commit(); !st) return st.error();
    return report_;
  }

 private:
  Error fail(const std::string& what) const { return Error{path_ + ": " + what}; }

  // Assigns a role to a channel carrying one of our types; checks namespace and schema text.
  Status classify(const mcap::Channel& channel, const mcap::Schema& schema) {
    for (std::size_t r = 0; r < std::size(kTypes); ++r) {
      if (schema.name != kTypes[r]) continue;
      if (!options_.ns.empty() && channel.topic != msgs::topic_name(msgs::topic(kTopicIds[r]), options_.ns)) {
        return Ok{};
      }
      if (!topics_[r].empty() && topics_[r] != channel.topic) {
        return fail("several " + std::string(kTypes[r]) + " topics (" + topics_[r] + ", " + channel.topic +
                    "): choose one recording with --namespace");
      }
      if (roles_.count(channel.id) != 0) return Ok{};
      auto expected = msgs::ros2msg_schema(kTypes[r]);
      if (!expected) return fail(expected.error().message);
      const std::string& text = expected.value();
      if (schema.encoding != "ros2msg" ||
          std::string_view(reinterpret_cast<const char*>(schema.data.data()), schema.data.size()) != text) {
        return fail("topic " + channel.topic + ": its " + std::string(kTypes[r]) +
                    " schema differs from this rbsim's (recorded by another version?): cannot export");
      }
      auto decoder = msgs::MessageDecoder::create(kTypes[r], text);
      if (!decoder) return fail(decoder.error().message);
      topics_[r] = channel.topic;
      decoders_.emplace(channel.id, std::move(decoder.value()));
      roles_.emplace(channel.id, static_cast<Role>(r));
    }
    return Ok{};
  }

  Status require_topics() {
    auto missing = [&](std::size_t r) {
      return fail("no " + std::string(kTypes[r]) + " topic" +
                  (options_.ns.empty() ? std::string() : " in namespace '" + options_.ns + "'") +
                  " (recorded by rbsim run --record?)");
    };
    if (topics_[0].empty()) return missing(0);
    if (!options_.csv.empty() && topics_[1].empty()) return missing(1);
    if (topics_[2].empty()) return missing(2);
    return Ok{};
  }

  Status message(const mcap::MessageEntry& e) {
    auto role = roles_.find(e.message.channel_id);
    if (role == roles_.end()) {
      if (e.channel == nullptr || e.schema == nullptr) return Ok{};
      if (Status st = classify(*e.channel, *e.schema); !st) return st;
      role = roles_.find(e.message.channel_id);
      if (role == roles_.end()) return Ok{};
    }
    const auto& data = e.message.data;
    const std::span<const std::byte> cdr(reinterpret_cast<const std::byte*>(data.data()), data.size());
    const msgs::MessageDecoder& decoder = decoders_.at(e.message.channel_id);
    const std::string where = "message at log time " + mcap_tools::seconds(e.message.log_time) + " s on " +
                              (e.channel != nullptr ? e.channel->topic : std::string("?"));
    if (Status st = decoder.decode(cdr, scalars_); !st) return fail(where + ": " + st.error().message);
    switch (role->second) {
      case Role::Scene:
        return scene_message(where);
      case Role::States:
        return states_message(where);
      case Role::Energy:
        return energy_message(where);
    }
    return Ok{};
  }

  Status scene_message(const std::string& where) {
    if (scene_) return Ok{};  // published once; a repeat carries the same constants
    SceneData s;
    Cursor c(scalars_);
    c.header();
    c.str();
    c.str();
    c.str();
    s.dt = c.f64();
    c.f64();
    c.u64();
    const std::uint64_t bodies = c.length();
    for (std::uint64_t b = 0; b < bodies && c.good(); ++b) {
      s.mass.push_back(c.f64());
      c.skip_floats(2 + 4);  // inertia, radius, color
      c.skip_floats(2 * c.length());
    }
    s.springs = c.length();
    for (std::uint64_t k = 0; k < s.springs; ++k) {
      c.i64();
      c.skip_floats(2);
      c.i64();
      c.skip_floats(2 + 2 + 4);
    }
    const std::uint64_t gravity = c.length();
    for (std::uint64_t g = 0; g < gravity; ++g) {
      const double ax = c.f64();
      s.gravity.emplace_back(ax, c.f64());
    }
    const std::uint64_t winds = c.length();
    for (std::uint64_t w = 0; w < winds; ++w) {
      c.skip_floats(3);
      c.i64();
    }
    c.boolean();
    c.skip_floats(3 + 4);
    if (!c.ok()) return fail(where + ": SceneDescription does not have the expected layout");
    scene_ = std::move(s);
    return Ok{};
  }

  Status begin_step(std::uint64_t step, const std::string& where) {
    if (current_ && current_->step == step) return Ok{};
    if (current_) {
      if (Status st = flush(); !st) return st;
    }
    if (last_step_ && step <= *last_step_) {
      return fail(where + ": step " + std::to_string(step) + " after step " + std::to_string(*last_step_) +
                  " (steps must increase)");
    }
    current_ = StepData{};
    current_->step = step;
    return Ok{};
  }

  Status states_message(const std::string& where) {
    if (scalars_.size() < 5) return fail(where + ": BodyStates does not have the expected layout");
    Cursor c(scalars_);
    c.header();
    const std::uint64_t step = c.u64();
    if (Status st = begin_step(step, where); !st) return st;
    if (current_->have_states)
      return fail(where + ": step " + std::to_string(step) + " has two BodyStates messages");
    const std::uint64_t n = c.length();
    std::vector<double>& v = current_->states;
    v.reserve(6 * n);
    for (std::uint64_t b = 0; b < n && c.good(); ++b) {
      c.i64();
      for (int k = 0; k < 6; ++k) v.push_back(c.f64());
    }
    if (!c.ok()) return fail(where + ": BodyStates does not have the expected layout");
    current_->have_states = true;
    return Ok{};
  }

  Status energy_message(const std::string& where) {
    if (scalars_.size() < 5) return fail(where + ": EnergyTerms does not have the expected layout");
    Cursor c(scalars_);
    c.header();
    const std::uint64_t step = c.u64();
    if (Status st = begin_step(step, where); !st) return st;
    StepData& d = *current_;
    if (d.have_energy)
      return fail(where + ": step " + std::to_string(step) + " has two EnergyTerms messages");
    const std::uint64_t n = c.length();
    d.quantities.reserve(6 * n);
    for (std::uint64_t b = 0; b < n && c.good(); ++b) {
      c.i64();
      for (int k = 0; k < 6; ++k) d.quantities.push_back(c.f64());
    }
    const std::uint64_t forces = c.length();
    for (std::uint64_t f = 0; f < forces; ++f) {
      const std::uint64_t kind = c.u64();
      c.i64();
      (kind == 0 ? d.gravity_u : d.spring_u).push_back(c.f64());
    }
    d.px = c.f64();
    d.py = c.f64();
    d.l = c.f64();
    c.f64();  // potential: associates differently from World::energy().potential()
    d.t_point = c.f64();
    d.t_spin = c.f64();
    c.f64();  // total
    if (!c.ok()) return fail(where + ": EnergyTerms does not have the expected layout");
    d.have_energy = true;
    return Ok{};
  }

  Status flush() {
    StepData d = std::move(*current_);
    current_.reset();
    const std::string at = "step " + std::to_string(d.step);
    if (!scene_) return fail(at + ": no SceneDescription message before it");
    const SceneData& s = *scene_;
    const bool need_states = csv_.is_open() || (energy_.is_open() && s.gravity.size() > 1);
    if ((need_states && !d.have_states) || !d.have_energy) {
      report_.warnings.push_back(at + ": no " + std::string(d.have_energy ? "BodyStates" : "EnergyTerms") +
                                 " message (recording cut short?): step skipped");
      return Ok{};
    }
    const std::size_t n = s.mass.size();
    if ((d.have_states && d.states.size() != 6 * n) || d.quantities.size() != 6 * n) {
      return fail(at + ": body count differs from the scene's (" + std::to_string(n) + ")");
    }
    if (d.spring_u.size() != s.springs || d.gravity_u.size() != s.gravity.size()) {
      return fail(at + ": force count differs from the scene's");
    }
    const auto step = static_cast<std::int64_t>(d.step);
    const double t = static_cast<double>(step) * s.dt;  // World::time()
    if (csv_.is_open()) {
      for (std::size_t b = 0; b < n; ++b) {
        const double* v = &d.states[6 * b];
        const double* q = &d.quantities[6 * b];
        const BodyState state{{v[0], v[1]}, v[2], {v[3], v[4]}, v[5]};
        const BodyQuantities quantities{{q[0], q[1]}, q[2], q[3], q[4], q[5]};
        append_body_row(csv_.rows(), step, t, static_cast<std::int32_t>(b), state, quantities);
      }
      if (Status st = csv_.flush_if_full(); !st) return st;
    }
    if (energy_.is_open()) {
      double u_gravity = 0.0;
      if (s.gravity.size() == 1) {
        u_gravity = d.gravity_u[0];
      } else {
        for (const auto& [ax, ay] : s.gravity) {
          for (std::size_t b = 0; b < n; ++b) {
            u_gravity -= s.mass[b] * (ax * d.states[6 * b] + ay * d.states[6 * b + 1]);
          }
        }
      }
      double u_spring = 0.0;
      for (double u : d.spring_u) u_spring += u;
      Energy e;
      e.u_gravity = u_gravity;
      e.u_spring = u_spring;
      e.t_point = d.t_point;
      e.t_spin = d.t_spin;
      append_energy_row(energy_.rows(), step, t, e, SceneTotals{{d.px, d.py}, d.l});
      if (Status st = energy_.flush_if_full(); !st) return st;
    }
    if (report_.steps == 0) report_.first_step = d.step;
    report_.last_step = d.step;
    ++report_.steps;
    last_step_ = d.step;
    return Ok{};
  }

  std::string path_;
  ExportOptions options_;
  ExportReport report_;
  std::string topics_[3];
  std::map<std::uint16_t, Role> roles_;
  std::map<std::uint16_t, msgs::MessageDecoder> decoders_;
  std::vector<Scalar> scalars_;
  std::optional<SceneData> scene_;
  std::optional<StepData> current_;
  std::optional<std::uint64_t> last_step_;
  CsvWriter csv_, energy_;
};

}  // namespace

Result<ExportReport> export_csv(const std::string& path, const ExportOptions& options) {
  return Exporter(path, options).run();
}

}  // namespace rbsim::log
