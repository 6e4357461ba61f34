// Golden logs: the record-every rule, finding a scene's FOSSSim reference output, and the
// verification a golden passes before it is written (independent of the simulator: everything
// here is recomputed from the scene file and the recorded body states with its own code).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>

#include "rbsim/golden.hpp"
#include "rbsim/io.hpp"
#include "rbsim/mcap.hpp"
#include "rbsim/recording.hpp"

namespace rbsim::check {

namespace fs = std::filesystem;

namespace {

std::string type_of(msgs::TopicId id) {
  return std::string(msgs::topic(id).type);
}

// `get` of every element of `items`, as doubles.
template <class T, class Get>
std::vector<double> field(const std::vector<T>& items, Get get) {
  std::vector<double> out;
  out.reserve(items.size());
  for (const T& item : items) out.push_back(static_cast<double>(get(item)));
  return out;
}

std::string g17(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}
std::string g3(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

// A golden log read whole (goldens are small), typed: the scene description and the per-step
// topics through the recording reader (topics found by type), the poses and the scene
// description's count and log time from one pass over those two topics.
template <class M>
struct TopicMessages {
  std::string topic;
  std::vector<M> messages;
  std::vector<mcap::Timestamp> log_time;
  void add(const M& m, mcap::Timestamp t) {
    messages.push_back(m);
    log_time.push_back(t);
  }
};
struct GoldenLog {
  std::optional<msgs::SceneMessage> scene;
  std::uint64_t scene_messages = 0;
  mcap::Timestamp scene_log_time = 0;  // of the first
  TopicMessages<msgs::BodyStatesMessage> states;
  TopicMessages<msgs::SpringStatesMessage> springs;
  TopicMessages<msgs::EnergyTermsMessage> energy;
  TopicMessages<msgs::PosesMessage> poses;
  TopicMessages<msgs::TfMessage> tf;
  TopicMessages<msgs::MarkerMessage> springs_marker;
  TopicMessages<std::vector<msgs::MarkerMessage>> markers;  // latched: one expected
};

Result<GoldenLog> read_log(const std::string& path) {
  log::RecordingOptions ro;
  ro.require_scene = false;  // a missing topic is a failed check, not an unreadable file
  ro.verify_crc = true;
  auto recording = log::Recording::open(path, ro);
  if (!recording) return recording.error();
  log::Recording& r = *recording.value();
  GoldenLog g;
  if (r.scene() != nullptr) g.scene = *r.scene();
  g.states.topic = r.topic(msgs::TopicId::BodyStates);
  g.springs.topic = r.topic(msgs::TopicId::SpringStates);
  g.energy.topic = r.topic(msgs::TopicId::Energy);
  if (Status st = r.read_steps([&](const log::RecordedStep& s) -> Status {
        if (s.body_states != nullptr) g.states.add(*s.body_states, s.log_time.body_states);
        if (s.spring_states != nullptr) g.springs.add(*s.spring_states, s.log_time.spring_states);
        if (s.energy != nullptr) g.energy.add(*s.energy, s.log_time.energy);
        return Ok{};
      });
      !st) {
    return st.error();
  }

  mcap::IndexedReader reader;
  if (auto st = reader.open(path); !st.ok()) return Error{path + ": " + st.message};
  // The topics the recording reader does not join, decoded here: poses, /tf, springs, markers.
  std::map<std::uint16_t, msgs::TopicId> route;
  std::map<msgs::TopicId, std::string> extra;
  for (const log::RecordedChannel& c : log::recorded_channels(reader)) {
    const msgs::TopicId id = c.spec->id;
    if (id == msgs::TopicId::Scene && c.channel->topic == r.topic(msgs::TopicId::Scene)) {
      route.emplace(c.channel->id, msgs::TopicId::Scene);
    } else if ((id == msgs::TopicId::Poses || id == msgs::TopicId::Tf || id == msgs::TopicId::Springs ||
                id == msgs::TopicId::Markers) &&
               c.problem.empty()) {
      std::string& topic = extra[id];
      if (!topic.empty() && topic != c.channel->topic) {
        return Error{path + ": two topics carry " + std::string(c.spec->type) + ": " + topic + " and " +
                     c.channel->topic};
      }
      topic = c.channel->topic;
      route.emplace(c.channel->id, id);
    }
  }
  g.poses.topic = extra[msgs::TopicId::Poses];
  g.tf.topic = extra[msgs::TopicId::Tf];
  g.springs_marker.topic = extra[msgs::TopicId::Springs];
  g.markers.topic = extra[msgs::TopicId::Markers];
  mcap::ReadMessagesOptions o;
  for (const std::string& t :
       {r.topic(msgs::TopicId::Scene), g.poses.topic, g.tf.topic, g.springs_marker.topic, g.markers.topic}) {
    if (!t.empty()) o.topics.push_back(t);
  }
  if (o.topics.empty()) return g;
  std::optional<Error> failure;
  msgs::PosesMessage poses;
  msgs::TfMessage tf;
  msgs::MarkerMessage marker;
  std::vector<msgs::MarkerMessage> markers;
  auto st = reader.read_messages(o, [&](const mcap::MessageEntry& e) {
    const auto it = route.find(e.message.channel_id);
    if (it == route.end()) return true;
    const auto cdr = std::as_bytes(std::span<const std::uint8_t>(e.message.data));
    const auto decoded = [&](Status d, const std::string& topic, std::size_t n) {
      if (!d)
        failure = Error{path + ": " + topic + " message " + std::to_string(n) + ": " + d.error().message};
      return static_cast<bool>(d);
    };
    switch (it->second) {
      case msgs::TopicId::Scene:
        if (g.scene_messages++ == 0) g.scene_log_time = e.message.log_time;
        return true;
      case msgs::TopicId::Poses:
        if (!decoded(msgs::decode_poses(cdr, poses), g.poses.topic, g.poses.messages.size())) return false;
        g.poses.add(poses, e.message.log_time);
        return true;
      case msgs::TopicId::Tf:
        if (!decoded(msgs::decode_tf(cdr, tf), g.tf.topic, g.tf.messages.size())) return false;
        g.tf.add(tf, e.message.log_time);
        return true;
      case msgs::TopicId::Springs:
        if (!decoded(msgs::decode_marker(cdr, marker), g.springs_marker.topic,
                     g.springs_marker.messages.size()))
          return false;
        g.springs_marker.add(marker, e.message.log_time);
        return true;
      default:
        if (!decoded(msgs::decode_marker_array(cdr, markers), g.markers.topic, g.markers.messages.size()))
          return false;
        g.markers.add(markers, e.message.log_time);
        return true;
    }
  });
  if (!st.ok()) return Error{path + ": " + st.message};
  if (failure) return *failure;
  return g;
}

// The largest deviation of a set of comparisons, and the first one outside its tolerance.
class Tally {
 public:
  void add(double got, double want, double tol, const std::function<std::string()>& where) {
    ++count_;
    double d = std::fabs(got - want);
    if (std::isnan(d)) d = got == want ? 0.0 : HUGE_VAL;
    if (d > max_) max_ = d;
    if (!(d <= tol) && fails_++ == 0) {
      first_ =
          where() + ": recorded " + g17(got) + ", expected " + g17(want) + " (tolerance " + g3(tol) + ")";
    }
  }
  void fail(const std::string& what) {
    if (fails_++ == 0) first_ = what;
  }
  bool ok() const { return fails_ == 0; }
  double max() const { return max_; }
  std::uint64_t count() const { return count_; }
  std::string summary() const {
    return ok() ? "max diff " + g3(max_)
                : std::to_string(fails_) + " of " + std::to_string(count_) + " outside tolerance, first " +
                      first_;
  }

 private:
  std::uint64_t count_ = 0, fails_ = 0;
  double max_ = 0.0;
  std::string first_;
};

struct Report {
  GoldenVerification& v;
  void line(bool ok, const std::string& what) {
    v.lines.push_back((ok ? "PASS " : "FAIL ") + what);
    if (!ok) failed = true;
  }
  void info(const std::string& what) { v.lines.push_back("info " + what); }
  bool failed = false;
};

// The scene's constant properties, recomputed from its file with this file's own code.
struct Model {
  std::vector<double> mass, inertia;
  std::vector<Vec2> center;                  // X at t = 0
  std::vector<std::vector<Vec2>> body_hull;  // body space
  std::vector<SpringDef> springs;
  std::vector<GravityDef> gravity;
};

Model model_of(const Scene& scene) {
  Model m;
  for (const BodyDef& b : scene.world.bodies) {
    double M = 0.0;
    Vec2 X(0.0, 0.0);
    for (std::size_t i = 0; i < b.hull.size(); ++i) {
      M += b.masses[i];
      X += b.masses[i] * b.hull[i];
    }
    X /= M;
    double I = 0.0;
    std::vector<Vec2> hull;
    for (std::size_t i = 0; i < b.hull.size(); ++i) {
      const Vec2 r = b.hull[i] - X;
      I += b.masses[i] * r.squaredNorm();
      hull.push_back(r);
    }
    m.mass.push_back(M);
    m.inertia.push_back(I);
    m.center.push_back(X);
    m.body_hull.push_back(std::move(hull));
  }
  m.springs = scene.world.springs;
  m.gravity = scene.world.gravity;
  return m;
}

struct State {
  std::vector<double> x, y, theta, vx, vy, omega;
};

struct SpringEnds {
  Vec2 end_i, end_j;
  double length = 0.0, potential = 0.0;
};

// Everything a step's energy, spring and pose messages should hold, from the state alone.
struct Terms {
  std::vector<double> px, py, l_point, l_spin, t_point, t_spin;
  std::vector<double> force_potential;  // each gravity field, then each spring
  std::vector<SpringEnds> springs;
  double momentum_x = 0.0, momentum_y = 0.0, angular = 0.0, potential = 0.0, kinetic_point = 0.0,
         kinetic_spin = 0.0, total = 0.0;
  double power = 0.0;  // sum F.V + tau omega of gravity and springs
  double scale = 0.0;  // sum of |term|: the size of the rounding error of the total
};

// The force of a spring on end i, pulling it towards end j when stretched (with l0 = 0 it is k d,
// no 0/0), added to the body at each end with its torque; d = end_j - end_i, length = |d|, arm_*
// the ends' offsets from their centres of mass.
void add_spring_force(const SpringDef& sp, const Vec2& d, double length, const Vec2& arm_i, const Vec2& arm_j,
                      std::vector<Vec2>& force, std::vector<double>& torque) {
  Vec2 f(0.0, 0.0);
  if (sp.rest_length == 0.0) {
    f = sp.stiffness * d;
  } else if (length > 0.0) {
    f = sp.stiffness * (length - sp.rest_length) / length * d;
  }
  if (sp.body_i >= 0) {
    force[sp.body_i] += f;
    torque[sp.body_i] += arm_i.x() * f.y() - arm_i.y() * f.x();
  }
  if (sp.body_j >= 0) {
    force[sp.body_j] -= f;
    torque[sp.body_j] -= arm_j.x() * f.y() - arm_j.y() * f.x();
  }
}

Terms terms_of(const Model& m, const State& s) {
  const std::size_t n = m.mass.size();
  Terms t;
  std::vector<Vec2> force(n, Vec2(0.0, 0.0));
  std::vector<double> torque(n, 0.0);
  for (std::size_t b = 0; b < n; ++b) {
    const double M = m.mass[b], I = m.inertia[b];
    const Vec2 X(s.x[b], s.y[b]), V(s.vx[b], s.vy[b]);
    t.px.push_back(M * V.x());
    t.py.push_back(M * V.y());
    t.l_point.push_back(M * (X.x() * V.y() - X.y() * V.x()));
    t.l_spin.push_back(I * s.omega[b]);
    t.t_point.push_back(0.5 * M * V.squaredNorm());
    t.t_spin.push_back(0.5 * I * s.omega[b] * s.omega[b]);
    t.momentum_x += t.px.back();
    t.momentum_y += t.py.back();
    t.angular += t.l_point.back() + t.l_spin.back();
    t.kinetic_point += t.t_point.back();
    t.kinetic_spin += t.t_spin.back();
  }
  for (const GravityDef& g : m.gravity) {
    double u = 0.0;
    for (std::size_t b = 0; b < n; ++b) {
      u -= m.mass[b] * (g.acceleration.x() * s.x[b] + g.acceleration.y() * s.y[b]);
      force[b] += m.mass[b] * g.acceleration;
      t.scale += std::fabs(m.mass[b] * g.acceleration.x() * s.x[b]) +
                 std::fabs(m.mass[b] * g.acceleration.y() * s.y[b]);
    }
    t.force_potential.push_back(u);
  }
  auto end = [&](std::int32_t body, const Vec2& anchor, Vec2& arm) {
    if (body < 0) {
      arm = Vec2(0.0, 0.0);
      return anchor;
    }
    const double c = std::cos(s.theta[body]), sn = std::sin(s.theta[body]);
    arm = Vec2(c * anchor.x() - sn * anchor.y(), sn * anchor.x() + c * anchor.y());
    return Vec2(s.x[body] + arm.x(), s.y[body] + arm.y());
  };
  for (const SpringDef& sp : m.springs) {
    Vec2 arm_i, arm_j;
    SpringEnds e;
    e.end_i = end(sp.body_i, sp.anchor_i, arm_i);
    e.end_j = end(sp.body_j, sp.anchor_j, arm_j);
    const Vec2 d = e.end_j - e.end_i;
    e.length = d.norm();
    const double stretch = e.length - sp.rest_length;
    e.potential = 0.5 * sp.stiffness * stretch * stretch;
    t.springs.push_back(e);
    t.force_potential.push_back(e.potential);
    t.scale += e.potential;
    add_spring_force(sp, d, e.length, arm_i, arm_j, force, torque);
  }
  for (double u : t.force_potential) t.potential += u;
  t.total = t.potential + t.kinetic_point + t.kinetic_spin;
  t.scale += t.kinetic_point + t.kinetic_spin;
  for (std::size_t b = 0; b < n; ++b) {
    t.power += force[b].x() * s.vx[b] + force[b].y() * s.vy[b] + torque[b] * s.omega[b];
  }
  return t;
}

// The verifier's own integrator, written from the spec (sections 4.6-4.8) and the README's
// conventions, independently of sim_core: every force summed directly, the wind over its sample
// points (sim_core uses a closed form), rotations by cos/sin per point.
void step_state(const Model& m, const Scene& scene, State& s) {
  const std::size_t n = m.mass.size();
  std::vector<Vec2> force(n, Vec2(0.0, 0.0));
  std::vector<double> torque(n, 0.0);
  auto rotate = [&](std::size_t b, const Vec2& p) {
    const double c = std::cos(s.theta[b]), sn = std::sin(s.theta[b]);
    return Vec2(c * p.x() - sn * p.y(), sn * p.x() + c * p.y());
  };
  for (const GravityDef& g : m.gravity) {
    for (std::size_t b = 0; b < n; ++b) force[b] += m.mass[b] * g.acceleration;
  }
  for (const SpringDef& sp : m.springs) {
    const Vec2 arm_i =
        sp.body_i < 0 ? Vec2(0.0, 0.0) : rotate(static_cast<std::size_t>(sp.body_i), sp.anchor_i);
    const Vec2 arm_j =
        sp.body_j < 0 ? Vec2(0.0, 0.0) : rotate(static_cast<std::size_t>(sp.body_j), sp.anchor_j);
    const Vec2 pi = sp.body_i < 0 ? sp.anchor_i : Vec2(s.x[sp.body_i], s.y[sp.body_i]) + arm_i;
    const Vec2 pj = sp.body_j < 0 ? sp.anchor_j : Vec2(s.x[sp.body_j], s.y[sp.body_j]) + arm_j;
    const Vec2 d = pj - pi;
    const double l = d.norm();
    add_spring_force(sp, d, l, arm_i, arm_j, force, torque);
  }
  // F = sum over edges i and sample points j of beta l_i / P ((v_wind - v_j) . n_i) n_i, the
  // hull clockwise, so n = (-e.y, e.x) / |e| points out; sample j at (j + 1/2) / P along the edge.
  for (const WindDef& w : scene.world.winds) {
    const int P = w.points_per_edge;
    for (std::size_t b = 0; b < n; ++b) {
      const std::vector<Vec2>& hull = m.body_hull[b];
      const Vec2 V(s.vx[b], s.vy[b]);
      for (std::size_t i = 0; i < hull.size(); ++i) {
        const Vec2 a = rotate(b, hull[i]), c = rotate(b, hull[(i + 1) % hull.size()]);
        const Vec2 e = c - a;
        const double l = e.norm();
        if (l == 0.0) continue;
        const Vec2 normal(-e.y() / l, e.x() / l);
        for (int j = 0; j < P; ++j) {
          const Vec2 r = a + ((j + 0.5) / P) * e;  // from the centre of mass
          const Vec2 v = V + Vec2(-s.omega[b] * r.y(), s.omega[b] * r.x());
          const Vec2 f = w.beta * (l / P) * (w.velocity - v).dot(normal) * normal;
          force[b] += f;
          torque[b] += r.x() * f.y() - r.y() * f.x();
        }
      }
    }
  }
  const double dt = scene.world.dt;
  const bool symplectic = scene.world.integrator == Integrator::SymplecticEuler;
  for (std::size_t b = 0; b < n; ++b) {
    const double vx = s.vx[b], vy = s.vy[b], w = s.omega[b];
    s.vx[b] += dt * force[b].x() / m.mass[b];
    s.vy[b] += dt * force[b].y() / m.mass[b];
    s.omega[b] += dt * torque[b] / m.inertia[b];
    s.x[b] += dt * (symplectic ? s.vx[b] : vx);
    s.y[b] += dt * (symplectic ? s.vy[b] : vy);
    s.theta[b] += dt * (symplectic ? s.omega[b] : w);
  }
}

std::uint64_t stamp_ns(std::uint64_t step, double dt) {
  const double ns = std::round(static_cast<double>(step) * dt * 1e9);
  return ns <= 0.0 ? 0 : static_cast<std::uint64_t>(ns);
}

bool same_file_contents(const fs::path& a, const std::string& bytes) {
  std::error_code ec;
  if (fs::file_size(a, ec) != bytes.size() || ec) return false;
  std::ifstream in(a, std::ios::binary);
  std::string other((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return other == bytes;
}

}  // namespace

std::int64_t golden_record_every(std::int64_t steps) {
  constexpr std::int64_t kTarget = 500;
  if (steps <= kTarget) return 1;
  const std::int64_t k0 = (steps + kTarget - 1) / kTarget;
  for (std::int64_t k = k0; k <= 2 * k0; ++k) {
    if (steps % k == 0) return k;
  }
  return k0;
}

FosssimMatch find_fosssim_reference(const std::string& scene_path, const std::string& fosssim_dir) {
  FosssimMatch match;
  std::ifstream in(scene_path, std::ios::binary);
  if (!in) return match;
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const fs::path scenes = fs::path(fosssim_dir) / "scenes";
  std::error_code ec;
  std::vector<fs::path> candidates;
  for (fs::recursive_directory_iterator it(scenes, ec), end; !ec && it != end; it.increment(ec)) {
    if (it->is_regular_file(ec) && it->path().extension() == ".xml") candidates.push_back(it->path());
  }
  std::sort(candidates.begin(), candidates.end());
  for (const fs::path& p : candidates) {
    if (!same_file_contents(p, bytes)) continue;
    match.scene = p.string();
    const fs::path rel = p.lexically_relative(scenes);
    for (const char* ext : {".bin.zst", ".bin"}) {
      fs::path ref = fs::path(fosssim_dir) / "reference" / rel.parent_path() / (rel.stem().string() + ext);
      if (fs::is_regular_file(ref, ec)) {
        match.reference = ref.string();
        return match;
      }
    }
    return match;
  }
  return match;
}

Result<std::int64_t> read_record_every(const std::string& golden_path) {
  auto log = read_log(golden_path);
  if (!log) return log.error();
  const auto& t = log->states.messages;
  if (t.empty()) return Error{golden_path + ": no body states recorded"};
  if (t.size() < 2) return std::int64_t{1};
  return static_cast<std::int64_t>(t[1].step - t[0].step);
}

Result<GoldenVerification> verify_golden(const std::string& scene_path, const std::string& golden_path,
                                         const GoldenVerifyOptions& options) {
  Result<Scene> loaded = load_scene(scene_path);
  if (!loaded) return loaded.error();
  const Scene& scene = loaded.value();
  auto log_result = read_log(golden_path);
  if (!log_result) return log_result.error();
  const GoldenLog& golden = log_result.value();

  GoldenVerification v;
  Report r{v};
  const Model model = model_of(scene);
  const std::size_t bodies = model.mass.size();
  const double dt = scene.world.dt;
  v.steps = scene.step_count();

  using msgs::TopicId;
  for (auto [missing, id] : {std::pair{!golden.scene, TopicId::Scene},
                             {golden.states.messages.empty(), TopicId::BodyStates},
                             {golden.springs.messages.empty(), TopicId::SpringStates},
                             {golden.energy.messages.empty(), TopicId::Energy}}) {
    if (missing) r.line(false, "recording: no " + type_of(id) + " messages");
  }
  if (r.failed) return v;
  const msgs::SceneMessage& desc = *golden.scene;
  const auto& states = golden.states;
  const auto& springs = golden.springs;
  const auto& energy = golden.energy;
  const bool poses = !golden.poses.messages.empty();
  const bool tf = !golden.tf.messages.empty();
  const bool springs_marker = !golden.springs_marker.messages.empty();

  // 1. The recorded scene description against the scene file.
  {
    Tally tally;
    auto exact = [&](double got, double want, const std::string& what) {
      tally.add(got, want, 0.0, [&] { return what; });
    };
    auto rel = [&](double got, double want, const std::string& what) {
      tally.add(got, want, 1e-12 * std::max(1.0, std::fabs(want)), [&] { return what; });
    };
    if (golden.scene_messages != 1 || golden.scene_log_time != 0) {
      tally.fail("expected one scene description at log time 0, found " +
                 std::to_string(golden.scene_messages));
    }
    if (desc.integrator != to_string(scene.world.integrator)) {
      tally.fail("integrator '" + desc.integrator + "', scene " + to_string(scene.world.integrator));
    }
    exact(desc.dt, dt, "dt");
    exact(desc.duration, scene.duration, "duration");
    exact(static_cast<double>(desc.step_count), static_cast<double>(v.steps), "step_count");
    using Body = msgs::SceneMessage::Body;
    const auto mass = field(desc.bodies, [](const Body& b) { return b.mass; });
    const auto inertia = field(desc.bodies, [](const Body& b) { return b.inertia; });
    const auto hull_n = field(desc.bodies, [](const Body& b) { return b.hull.size(); });
    std::vector<double> hx, hy;
    for (const Body& b : desc.bodies) {
      for (const Vec2& p : b.hull) {
        hx.push_back(p.x());
        hy.push_back(p.y());
      }
    }
    exact(static_cast<double>(mass.size()), static_cast<double>(bodies), "body count");
    std::size_t h = 0;
    for (std::size_t b = 0; b < std::min(bodies, mass.size()); ++b) {
      const std::string id = "body " + std::to_string(b);
      rel(mass[b], model.mass[b], id + " mass");
      rel(inertia[b], model.inertia[b], id + " inertia");
      exact(hull_n[b], static_cast<double>(model.body_hull[b].size()), id + " hull vertex count");
      for (std::size_t k = 0; k < model.body_hull[b].size() && h < hx.size(); ++k, ++h) {
        const Vec2& want = model.body_hull[b][k];
        rel(hx[h], want.x(), id + " hull vertex " + std::to_string(k) + " x");
        rel(hy[h], want.y(), id + " hull vertex " + std::to_string(k) + " y");
      }
    }
    const auto& ds = desc.springs;
    const auto bi = field(ds, [](const SpringDef& d) { return d.body_i; });
    const auto bj = field(ds, [](const SpringDef& d) { return d.body_j; });
    const auto aix = field(ds, [](const SpringDef& d) { return d.anchor_i.x(); });
    const auto aiy = field(ds, [](const SpringDef& d) { return d.anchor_i.y(); });
    const auto ajx = field(ds, [](const SpringDef& d) { return d.anchor_j.x(); });
    const auto ajy = field(ds, [](const SpringDef& d) { return d.anchor_j.y(); });
    const auto k = field(ds, [](const SpringDef& d) { return d.stiffness; });
    const auto l0 = field(ds, [](const SpringDef& d) { return d.rest_length; });
    exact(static_cast<double>(k.size()), static_cast<double>(model.springs.size()), "spring count");
    for (std::size_t s = 0; s < std::min(k.size(), model.springs.size()); ++s) {
      const SpringDef& sp = model.springs[s];
      const std::string id = "spring " + std::to_string(s);
      exact(bi[s], sp.body_i, id + " body_i");
      exact(bj[s], sp.body_j, id + " body_j");
      exact(aix[s], sp.anchor_i.x(), id + " anchor_i.x");
      exact(aiy[s], sp.anchor_i.y(), id + " anchor_i.y");
      exact(ajx[s], sp.anchor_j.x(), id + " anchor_j.x");
      exact(ajy[s], sp.anchor_j.y(), id + " anchor_j.y");
      exact(k[s], sp.stiffness, id + " stiffness");
      exact(l0[s], sp.rest_length, id + " rest_length");
    }
    // Colours travel as float32 (std_msgs/ColorRGBA): the scene's, rounded so, exactly.
    auto colour = [&](const Color& got, const Color& want, const std::string& id) {
      exact(got.r, static_cast<float>(want.r), id + " colour r");
      exact(got.g, static_cast<float>(want.g), id + " colour g");
      exact(got.b, static_cast<float>(want.b), id + " colour b");
    };
    for (std::size_t b = 0; b < std::min(desc.bodies.size(), scene.body_colors.size()); ++b)
      colour(desc.bodies[b].color, scene.body_colors[b], "body " + std::to_string(b));
    for (std::size_t s = 0; s < std::min(desc.spring_colors.size(), scene.spring_colors.size()); ++s)
      colour(desc.spring_colors[s], scene.spring_colors[s], "spring " + std::to_string(s));
    const auto gx = field(desc.gravity, [](const GravityDef& d) { return d.acceleration.x(); });
    const auto gy = field(desc.gravity, [](const GravityDef& d) { return d.acceleration.y(); });
    exact(static_cast<double>(gx.size()), static_cast<double>(model.gravity.size()), "gravity count");
    for (std::size_t g = 0; g < std::min(gx.size(), model.gravity.size()); ++g) {
      exact(gx[g], model.gravity[g].acceleration.x(), "gravity " + std::to_string(g) + " x");
      exact(gy[g], model.gravity[g].acceleration.y(), "gravity " + std::to_string(g) + " y");
    }
    const auto beta = field(desc.winds, [](const WindDef& d) { return d.beta; });
    const auto wx = field(desc.winds, [](const WindDef& d) { return d.velocity.x(); });
    const auto wy = field(desc.winds, [](const WindDef& d) { return d.velocity.y(); });
    const auto ppe = field(desc.winds, [](const WindDef& d) { return d.points_per_edge; });
    exact(static_cast<double>(beta.size()), static_cast<double>(scene.world.winds.size()), "wind count");
    for (std::size_t w = 0; w < std::min(beta.size(), scene.world.winds.size()); ++w) {
      const WindDef& wd = scene.world.winds[w];
      exact(beta[w], wd.beta, "wind " + std::to_string(w) + " beta");
      exact(wx[w], wd.velocity.x(), "wind " + std::to_string(w) + " velocity.x");
      exact(wy[w], wd.velocity.y(), "wind " + std::to_string(w) + " velocity.y");
      exact(ppe[w], wd.points_per_edge, "wind " + std::to_string(w) + " points_per_edge");
    }
    r.line(tally.ok(), "scene description: " + std::to_string(bodies) +
                           " bodies (M, I and body-space hulls recomputed "
                           "from the vertices), " +
                           std::to_string(model.springs.size()) + " springs, colours, " +
                           std::to_string(model.gravity.size()) + " gravity, " +
                           std::to_string(scene.world.winds.size()) + " wind, dt " + g17(dt) + ", " +
                           to_string(scene.world.integrator) + ", " + std::to_string(v.steps) +
                           " steps: " + tally.summary());
    // With other counts the recording cannot be read against this scene; with other values it
    // can, and the checks below show what they break.
    if (mass.size() != bodies || k.size() != model.springs.size() || gx.size() != model.gravity.size() ||
        hull_n.size() != bodies) {
      return v;
    }
  }

  // 2. The recording: steps 0, K, 2K, ... up to the end of the run, stamped t = step * dt, the
  //    same steps on every per-step topic, the initial state from the scene.
  std::vector<State> state(states.messages.size());
  std::vector<std::uint64_t> steps(states.messages.size());
  {
    Tally tally;
    using Body = msgs::BodyStatesMessage::Body;
    for (std::size_t m = 0; m < states.messages.size(); ++m) {
      const msgs::BodyStatesMessage& msg = states.messages[m];
      steps[m] = msg.step;
      State& s = state[m];
      s.x = field(msg.bodies, [](const Body& b) { return b.state.position.x(); });
      s.y = field(msg.bodies, [](const Body& b) { return b.state.position.y(); });
      s.theta = field(msg.bodies, [](const Body& b) { return b.state.theta; });
      s.vx = field(msg.bodies, [](const Body& b) { return b.state.velocity.x(); });
      s.vy = field(msg.bodies, [](const Body& b) { return b.state.velocity.y(); });
      s.omega = field(msg.bodies, [](const Body& b) { return b.state.omega; });
      const auto ids = field(msg.bodies, [](const Body& b) { return b.id; });
      if (s.x.size() != bodies || s.omega.size() != bodies || ids.size() != bodies) {
        tally.fail("step message " + std::to_string(m) + " holds " + std::to_string(s.x.size()) + " bodies");
        state.resize(m);
        steps.resize(m);
        break;
      }
      for (std::size_t b = 0; b < bodies; ++b) {
        if (ids[b] != static_cast<double>(b))
          tally.fail("message " + std::to_string(m) + " body ids out of order");
      }
    }
    const std::uint64_t K = steps.size() >= 2 ? steps[1] - steps[0] : 1;
    v.record_every = static_cast<std::int64_t>(K);
    v.last_step = steps.empty() ? 0 : static_cast<std::int64_t>(steps.back());
    if (steps.empty() || steps[0] != 0) tally.fail("the first recorded step is not step 0");
    for (std::size_t m = 0; m < steps.size(); ++m) {
      if (steps[m] != m * K) {
        tally.fail("recorded step " + std::to_string(steps[m]) + " where step " + std::to_string(m * K) +
                   " was expected");
        break;
      }
      const std::uint64_t ns = stamp_ns(steps[m], dt);
      tally.add(static_cast<double>(states.log_time[m]), static_cast<double>(ns), 0.0,
                [&] { return "step " + std::to_string(steps[m]) + " log time"; });
      const double sec = states.messages[m].stamp.sec, nsec = states.messages[m].stamp.nanosec;
      tally.add(sec * 1e9 + nsec, static_cast<double>(ns), 0.0,
                [&] { return "step " + std::to_string(steps[m]) + " header stamp"; });
    }
    if (options.whole_run && !steps.empty() &&
        (steps.back() > static_cast<std::uint64_t>(v.steps) ||
         static_cast<std::uint64_t>(v.steps) - steps.back() >= std::max<std::uint64_t>(K, 1))) {
      tally.fail("the recording ends at step " + std::to_string(steps.back()) + ", the scene runs " +
                 std::to_string(v.steps) + " steps");
    }
    // The other per-step topics: their topic, log times and steps (none for poses).
    struct Other {
      const std::string& topic;
      const std::vector<mcap::Timestamp>& log_time;
      std::vector<std::uint64_t> steps;
    };
    std::vector<Other> others = {
        {springs.topic, springs.log_time, {}},
        {energy.topic, energy.log_time, {}},
    };
    for (const auto& msg : springs.messages) others[0].steps.push_back(msg.step);
    for (const auto& msg : energy.messages) others[1].steps.push_back(msg.step);
    if (poses) others.push_back({golden.poses.topic, golden.poses.log_time, {}});
    if (tf) others.push_back({golden.tf.topic, golden.tf.log_time, {}});
    if (springs_marker) others.push_back({golden.springs_marker.topic, golden.springs_marker.log_time, {}});
    for (const Other& t : others) {
      if (t.log_time.size() != states.messages.size()) {
        tally.fail(t.topic + " has " + std::to_string(t.log_time.size()) + " messages, " + states.topic +
                   " " + std::to_string(states.messages.size()));
        continue;
      }
      for (std::size_t m = 0; m < steps.size(); ++m) {
        tally.add(static_cast<double>(t.log_time[m]), static_cast<double>(states.log_time[m]), 0.0,
                  [&] { return t.topic + " message " + std::to_string(m) + " log time"; });
        if (!t.steps.empty()) {
          tally.add(static_cast<double>(t.steps[m]), static_cast<double>(steps[m]), 0.0,
                    [&] { return t.topic + " message " + std::to_string(m) + " step"; });
        }
      }
    }
    if (!state.empty()) {
      const State& s0 = state[0];
      for (std::size_t b = 0; b < bodies; ++b) {
        const BodyDef& def = scene.world.bodies[b];
        const std::string id = "step 0 body " + std::to_string(b);
        const double tol = 1e-12 * std::max(1.0, model.center[b].norm());
        tally.add(s0.x[b], model.center[b].x(), tol, [&] { return id + " x"; });
        tally.add(s0.y[b], model.center[b].y(), tol, [&] { return id + " y"; });
        tally.add(s0.theta[b], 0.0, 0.0, [&] { return id + " theta"; });
        tally.add(s0.vx[b], def.velocity.x(), 0.0, [&] { return id + " vx"; });
        tally.add(s0.vy[b], def.velocity.y(), 0.0, [&] { return id + " vy"; });
        tally.add(s0.omega[b], def.omega, 0.0, [&] { return id + " omega"; });
      }
    }
    r.line(tally.ok(), "recording: steps 0.." + std::to_string(v.last_step) + " every " + std::to_string(K) +
                           " (" + std::to_string(steps.size()) +
                           " per topic), stamps = step * dt, initial state = scene: " + tally.summary());
    if (!tally.ok()) return v;
  }

  // 3. Every recorded energy, spring and pose term against its recomputation from the state.
  std::vector<Terms> terms;
  for (const State& s : state) terms.push_back(terms_of(model, s));
  {
    const double rtol = options.recompute_rtol;
    Tally e, sp, po, tfs, spm;
    // Body frames are "<namespace>/body_<i>", the namespace that of the body-state topic.
    std::string ns = states.topic.substr(0, states.topic.rfind('/'));
    if (!ns.empty()) ns.erase(0, 1);
    for (std::size_t m = 0; m < state.size(); ++m) {
      const Terms& t = terms[m];
      const std::string at = "step " + std::to_string(steps[m]);
      auto near = [&](Tally& tally, double got, double want, const char* what, std::size_t i = SIZE_MAX) {
        tally.add(got, want, rtol * std::max(1.0, std::fabs(want)), [&] {
          return at + " " + what + (i == SIZE_MAX ? std::string() : " [" + std::to_string(i) + "]");
        });
      };
      auto each = [&](Tally& tally, const std::vector<double>& got, const char* path,
                      const std::vector<double>& want) {
        if (got.size() != want.size()) {
          tally.fail(at + " " + path + ": " + std::to_string(got.size()) + " values, expected " +
                     std::to_string(want.size()));
          return;
        }
        for (std::size_t i = 0; i < got.size(); ++i) near(tally, got[i], want[i], path, i);
      };
      using EBody = msgs::EnergyTermsMessage::Body;
      const msgs::EnergyTermsMessage& en = energy.messages[m];
      each(e, field(en.bodies, [](const EBody& b) { return b.momentum.x(); }), "bodies[].momentum.x", t.px);
      each(e, field(en.bodies, [](const EBody& b) { return b.momentum.y(); }), "bodies[].momentum.y", t.py);
      each(e, field(en.bodies, [](const EBody& b) { return b.l_point; }), "bodies[].l_point", t.l_point);
      each(e, field(en.bodies, [](const EBody& b) { return b.l_spin; }), "bodies[].l_spin", t.l_spin);
      each(e, field(en.bodies, [](const EBody& b) { return b.t_point; }), "bodies[].t_point", t.t_point);
      each(e, field(en.bodies, [](const EBody& b) { return b.t_spin; }), "bodies[].t_spin", t.t_spin);
      each(e, field(en.forces, [](const msgs::EnergyTermsMessage::Force& f) { return f.potential; }),
           "forces[].potential", t.force_potential);
      near(e, en.momentum.x(), t.momentum_x, "momentum.x");
      near(e, en.momentum.y(), t.momentum_y, "momentum.y");
      near(e, en.angular_momentum, t.angular, "angular_momentum");
      near(e, en.potential, t.potential, "potential");
      near(e, en.kinetic_point, t.kinetic_point, "kinetic_point");
      near(e, en.kinetic_spin, t.kinetic_spin, "kinetic_spin");
      near(e, en.total, t.total, "total");
      if (en.has_split) {
        double ug = 0.0, us = 0.0;
        for (std::size_t i = 0; i < t.force_potential.size(); ++i) {
          (i < model.gravity.size() ? ug : us) += t.force_potential[i];
        }
        near(e, en.potential_gravity, ug, "potential_gravity");
        near(e, en.potential_spring, us, "potential_spring");
        near(e, en.potential_gravity + en.potential_spring, t.potential,
             "potential_gravity + potential_spring");
      }
      std::vector<double> ex, ey, fx, fy, len, rest, pot;
      for (std::size_t k = 0; k < t.springs.size(); ++k) {
        ex.push_back(t.springs[k].end_i.x());
        ey.push_back(t.springs[k].end_i.y());
        fx.push_back(t.springs[k].end_j.x());
        fy.push_back(t.springs[k].end_j.y());
        len.push_back(t.springs[k].length);
        rest.push_back(model.springs[k].rest_length);
        pot.push_back(t.springs[k].potential);
      }
      using SState = msgs::SpringStatesMessage::Spring;
      const auto& ss = springs.messages[m].springs;
      each(sp, field(ss, [](const SState& x) { return x.end_i.x(); }), "springs[].end_i.x", ex);
      each(sp, field(ss, [](const SState& x) { return x.end_i.y(); }), "springs[].end_i.y", ey);
      each(sp, field(ss, [](const SState& x) { return x.end_j.x(); }), "springs[].end_j.x", fx);
      each(sp, field(ss, [](const SState& x) { return x.end_j.y(); }), "springs[].end_j.y", fy);
      each(sp, field(ss, [](const SState& x) { return x.length; }), "springs[].length", len);
      each(sp, field(ss, [](const SState& x) { return x.rest_length; }), "springs[].rest_length", rest);
      each(sp, field(ss, [](const SState& x) { return x.potential; }), "springs[].potential", pot);
      if (poses) {
        using Pose = msgs::PosesMessage::Pose;
        const auto& ps = golden.poses.messages[m].poses;
        std::vector<double> qz, qw;
        for (std::size_t b = 0; b < bodies; ++b) {
          qz.push_back(std::sin(0.5 * state[m].theta[b]));
          qw.push_back(std::cos(0.5 * state[m].theta[b]));
        }
        each(po, field(ps, [](const Pose& p) { return p.x; }), "poses[].position.x", state[m].x);
        each(po, field(ps, [](const Pose& p) { return p.y; }), "poses[].position.y", state[m].y);
        each(po, field(ps, [](const Pose& p) { return p.qz; }), "poses[].orientation.z", qz);
        each(po, field(ps, [](const Pose& p) { return p.qw; }), "poses[].orientation.w", qw);
      }
      if (tf) {
        using T = msgs::TfMessage::Transform;
        const auto& ts = golden.tf.messages[m].transforms;
        std::vector<double> qz, qw, zero(bodies, 0.0);
        for (std::size_t b = 0; b < bodies; ++b) {
          qz.push_back(std::sin(0.5 * state[m].theta[b]));
          qw.push_back(std::cos(0.5 * state[m].theta[b]));
        }
        each(tfs, field(ts, [](const T& x) { return x.x; }), "transforms[].translation.x", state[m].x);
        each(tfs, field(ts, [](const T& x) { return x.y; }), "transforms[].translation.y", state[m].y);
        each(tfs, field(ts, [](const T& x) { return x.z; }), "transforms[].translation.z", zero);
        each(tfs, field(ts, [](const T& x) { return x.qx; }), "transforms[].rotation.x", zero);
        each(tfs, field(ts, [](const T& x) { return x.qy; }), "transforms[].rotation.y", zero);
        each(tfs, field(ts, [](const T& x) { return x.qz; }), "transforms[].rotation.z", qz);
        each(tfs, field(ts, [](const T& x) { return x.qw; }), "transforms[].rotation.w", qw);
        const auto& stamp = states.messages[m].stamp;
        for (std::size_t b = 0; b < ts.size(); ++b) {
          const std::string frame = (ns.empty() ? "" : ns + "/") + "body_" + std::to_string(b);
          if (ts[b].frame_id != "world" || ts[b].child_frame_id != frame || ts[b].stamp.sec != stamp.sec ||
              ts[b].stamp.nanosec != stamp.nanosec) {
            tfs.fail(at + " transforms[" + std::to_string(b) + "]: " + ts[b].frame_id + " -> " +
                     ts[b].child_frame_id + ", expected world -> " + frame + " at the body states' stamp");
            break;
          }
        }
      }
      if (springs_marker) {
        const msgs::MarkerMessage& mk = golden.springs_marker.messages[m];
        std::vector<double> px, py, want_x, want_y, cr, want_cr;
        for (const Vec2& p : mk.points) {
          px.push_back(p.x());
          py.push_back(p.y());
        }
        for (std::size_t k = 0; k < t.springs.size(); ++k) {
          want_x.insert(want_x.end(), {t.springs[k].end_i.x(), t.springs[k].end_j.x()});
          want_y.insert(want_y.end(), {t.springs[k].end_i.y(), t.springs[k].end_j.y()});
          const Color c = k < desc.spring_colors.size() ? desc.spring_colors[k] : Color{};
          for (int end = 0; end < 2; ++end) want_cr.insert(want_cr.end(), {c.r, c.g, c.b});
        }
        for (const auto& c : mk.colors) cr.insert(cr.end(), {c[0], c[1], c[2]});
        if (mk.colors.empty()) {  // one colour for every spring: the marker's
          for (std::size_t p = 0; p < mk.points.size(); ++p)
            cr.insert(cr.end(), {mk.color[0], mk.color[1], mk.color[2]});
        }
        each(spm, px, "points[].x", want_x);
        each(spm, py, "points[].y", want_y);
        each(spm, cr, "colors[].rgb", want_cr);
        if (mk.type != msgs::kMarkerLineList || mk.frame_id != "world") {
          spm.fail(at + ": springs marker of type " + std::to_string(mk.type) + " in frame " + mk.frame_id +
                   ", expected a LINE_LIST in world");
        }
      }
    }
    const std::string tol = " (tolerance " + g3(rtol) + " x max(1, |value|))";
    r.line(e.ok(),
           "energy terms: P, L_point, L_spin, T_point, T_spin per body, U per force and the totals of " +
               std::to_string(state.size()) + " steps recomputed from the recorded states" + tol + ": " +
               e.summary());
    r.line(sp.ok(), "spring states: endpoints, lengths and potentials recomputed from the recorded poses" +
                        tol + ": " + sp.summary());
    if (poses) r.line(po.ok(), "poses: positions and orientation quaternions" + tol + ": " + po.summary());
    if (tf) {
      r.line(tfs.ok(), "tf: world -> body frame transforms equal to the recorded body states" + tol + ": " +
                           tfs.summary());
    }
    if (springs_marker) {
      r.line(spm.ok(), "springs marker: line ends recomputed from the recorded states, scene colours" + tol +
                           ": " + spm.summary());
    }
  }
  // The latched markers: sent once, at step 0; per body its hull filled with counter-clockwise
  // triangles that tile it (areas summing to the hull's, each centroid inside the hull) and its
  // closed outline, in the body's frame and colour; the fixed spring anchors in world.
  const bool old_markers = !golden.markers.messages.empty() && !golden.markers.messages[0].empty() &&
                           !golden.markers.messages[0][0].frame_locked;
  if (old_markers) {
    r.info("markers: the per-step outlines of recordings made before the latched markers, not verified");
  } else if (!golden.markers.messages.empty()) {
    Tally tally;
    std::string ns = states.topic.substr(0, states.topic.rfind('/'));
    if (!ns.empty()) ns.erase(0, 1);
    if (golden.markers.messages.size() != 1 || golden.markers.log_time[0] != 0) {
      tally.fail("expected one MarkerArray at log time 0, found " +
                 std::to_string(golden.markers.messages.size()));
    }
    const auto& ms = golden.markers.messages[0];
    std::vector<Vec2> anchors;
    for (const SpringDef& sp : model.springs) {
      if (sp.body_i == kFixed) anchors.push_back(sp.anchor_i);
      if (sp.body_j == kFixed) anchors.push_back(sp.anchor_j);
    }
    const std::size_t want = 2 * bodies + (anchors.empty() ? 0 : 1);
    if (ms.size() != want) {
      tally.fail(std::to_string(ms.size()) + " markers, expected " + std::to_string(want));
    } else {
      const auto cross = [](const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); };
      for (std::size_t b = 0; b < bodies; ++b) {
        const std::string id = "body " + std::to_string(b);
        const std::vector<Vec2>& hull = model.body_hull[b];
        const std::string frame = (ns.empty() ? "" : ns + "/") + "body_" + std::to_string(b);
        const msgs::MarkerMessage& fill = ms[2 * b];
        const msgs::MarkerMessage& line = ms[2 * b + 1];
        const Color c = desc.bodies[b].color;
        for (const msgs::MarkerMessage* mk : {&fill, &line}) {
          if (mk->frame_id != frame || !mk->frame_locked || mk->lifetime.sec != 0 ||
              mk->lifetime.nanosec != 0 || mk->color[0] != static_cast<float>(c.r) ||
              mk->color[1] != static_cast<float>(c.g) || mk->color[2] != static_cast<float>(c.b)) {
            tally.fail(id + ": marker in frame '" + mk->frame_id + "', expected '" + frame +
                       "', frame-locked, lifetime 0, the body's colour");
          }
        }
        double area = 0.0, tiles = 0.0;
        for (std::size_t k = 0; k < hull.size(); ++k)
          area += 0.5 * cross(hull[k], hull[(k + 1) % hull.size()]);
        const auto inside = [&](const Vec2& q) {  // winding number of the hull around q
          int wn = 0;
          for (std::size_t k = 0; k < hull.size(); ++k) {
            const Vec2& a = hull[k];
            const Vec2& e = hull[(k + 1) % hull.size()];
            const double side = cross(e - a, q - a);
            if (a.y() <= q.y() && e.y() > q.y() && side > 0) ++wn;
            if (a.y() > q.y() && e.y() <= q.y() && side < 0) --wn;
          }
          return wn != 0;
        };
        if (fill.type != msgs::kMarkerTriangleList || fill.points.size() % 3 != 0) {
          tally.fail(id + ": hull marker is not a TRIANGLE_LIST");
          continue;
        }
        for (std::size_t k = 0; k + 2 < fill.points.size(); k += 3) {
          const Vec2 &p0 = fill.points[k], &p1 = fill.points[k + 1], &p2 = fill.points[k + 2];
          const double a = 0.5 * cross(p1 - p0, p2 - p0);
          if (a < 0.0) tally.fail(id + ": triangle " + std::to_string(k / 3) + " is clockwise");
          if (!inside((p0 + p1 + p2) / 3.0))
            tally.fail(id + ": triangle " + std::to_string(k / 3) + " lies outside the hull");
          tiles += a;
        }
        tally.add(tiles, std::fabs(area), 1e-9 * std::max(1e-12, std::fabs(area)),
                  [&] { return id + " filled area"; });
        std::vector<Vec2> outline = hull;
        if (!hull.empty()) outline.push_back(hull.front());
        if (line.type != msgs::kMarkerLineStrip || line.points.size() != outline.size()) {
          tally.fail(id + ": outline is not the closed hull as a LINE_STRIP");
          continue;
        }
        for (std::size_t k = 0; k < outline.size(); ++k) {
          const double tol = 1e-12 * std::max(1.0, outline[k].norm());
          tally.add(line.points[k].x(), outline[k].x(), tol, [&] { return id + " outline x"; });
          tally.add(line.points[k].y(), outline[k].y(), tol, [&] { return id + " outline y"; });
        }
        tally.add(line.scale_x, 2.0 * desc.bodies[b].radius, 0.0, [&] { return id + " outline width"; });
      }
      if (!anchors.empty()) {
        const msgs::MarkerMessage& a = ms.back();
        if (a.frame_id != "world" || a.points.size() != anchors.size()) {
          tally.fail("spring anchors: " + std::to_string(a.points.size()) + " in '" + a.frame_id +
                     "', expected " + std::to_string(anchors.size()) + " in world");
        } else {
          for (std::size_t k = 0; k < anchors.size(); ++k) {
            tally.add(a.points[k].x(), anchors[k].x(), 0.0,
                      [&] { return "anchor " + std::to_string(k) + " x"; });
            tally.add(a.points[k].y(), anchors[k].y(), 0.0,
                      [&] { return "anchor " + std::to_string(k) + " y"; });
          }
        }
      }
    }
    r.line(tally.ok(), "markers: once at step 0, " + std::to_string(bodies) +
                           " hulls tiled by counter-clockwise triangles inside them (areas summing to the "
                           "hull's), closed outlines of width 2 r, body frames and colours, " +
                           std::to_string(anchors.size()) + " fixed anchors: " + tally.summary());
  }

  // 4. The dynamics, re-integrated independently: from each recorded state, K steps of the
  //    verifier's own integrator must land on the next recorded state.
  {
    Tally tally;
    const double tol = options.integration_tol;
    for (std::size_t m = 0; m + 1 < state.size(); ++m) {
      State s = state[m];
      for (std::uint64_t k = steps[m]; k < steps[m + 1]; ++k) step_state(model, scene, s);
      const State& want = state[m + 1];
      for (std::size_t b = 0; b < bodies; ++b) {
        const std::string at = "step " + std::to_string(steps[m + 1]) + " body " + std::to_string(b);
        auto add = [&](double got, double expected, const char* what) {
          tally.add(expected, got, tol * std::max(1.0, std::fabs(got)), [&] { return at + " " + what; });
        };
        add(s.x[b], want.x[b], "x");
        add(s.y[b], want.y[b], "y");
        add(s.theta[b], want.theta[b], "theta");
        add(s.vx[b], want.vx[b], "vx");
        add(s.vy[b], want.vy[b], "vy");
        add(s.omega[b], want.omega[b], "omega");
      }
    }
    r.line(tally.ok(),
           "independent integration: from each recorded state, " + std::to_string(v.record_every) +
               " steps of the verifier's own " + to_string(scene.world.integrator) +
               " (gravity, springs, wind summed over its sample points) reach the next recorded state "
               "(tolerance " +
               g3(tol) + " x max(1, |value|)): " + tally.summary());
    if (tally.ok()) v.rule = "independent-integration";
  }

  // 5. Against an independent result: the reference solver's output, or energy conservation.
  const FosssimMatch match =
      options.fosssim_dir.empty() ? FosssimMatch{} : find_fosssim_reference(scene_path, options.fosssim_dir);
  if (!match.reference.empty()) {
    v.rule = "fosssim-reference, " + v.rule;
    r.info("the scene is FOSSSim's " + match.scene + ", reference output " + match.reference);
    Result<std::vector<std::byte>> bytes = read_file(match.reference);
    if (!bytes) return bytes.error();
    Result<FosssimLog> ref = parse_fosssim(bytes.value(), static_cast<std::int32_t>(bodies));
    if (!ref) return Error{match.reference + ": " + ref.error().message};
    Result<GradeReport> graded = grade(scene, ref.value());
    if (!graded) return graded.error();
    const GradeReport& gr = graded.value();
    r.line(gr.passed, "grade (the reference's rule, as rbsim grade): " + std::to_string(gr.steps) +
                          " steps, max step diff " + g3(gr.max_step_diff) + ", summed " +
                          g3(gr.sum_step_diff) + ", max quantity diff " + g3(gr.max_quantity_diff) +
                          (gr.passed ? "" : ": " + gr.message));
    Tally st, q;
    const FosssimLog& rl = ref.value();
    for (std::size_t b = 0; b < bodies; ++b) {
      const std::string id = "body " + std::to_string(b);
      q.add(desc.bodies[b].mass, rl.mass[b], options.quantity_tol, [&] { return id + " M"; });
      q.add(desc.bodies[b].inertia, rl.inertia[b], options.quantity_tol, [&] { return id + " I"; });
    }
    for (std::size_t m = 0; m < state.size(); ++m) {
      if (steps[m] >= rl.frames.size()) {
        st.fail("step " + std::to_string(steps[m]) + " is past the reference's " +
                std::to_string(rl.frames.size() - 1));
        break;
      }
      const FosssimFrame& f = rl.frames[steps[m]];
      const State& s = state[m];
      const std::string at = "step " + std::to_string(steps[m]) + " body ";
      for (std::size_t b = 0; b < bodies; ++b) {
        const BodyState& want = f.states[b];
        const double tol = options.state_tol;
        auto where = [&](const char* what) {
          return [&, what] { return at + std::to_string(b) + " " + what; };
        };
        st.add(s.x[b], want.position.x(), tol, where("x"));
        st.add(s.y[b], want.position.y(), tol, where("y"));
        st.add(s.theta[b], want.theta, tol, where("theta"));
        st.add(s.vx[b], want.velocity.x(), tol, where("vx"));
        st.add(s.vy[b], want.velocity.y(), tol, where("vy"));
        st.add(s.omega[b], want.omega, tol, where("omega"));
        const BodyQuantities& wq = f.quantities[b];
        const double qt = options.quantity_tol;
        const msgs::EnergyTermsMessage::Body& eb = energy.messages[m].bodies[b];
        q.add(eb.momentum.x(), wq.momentum.x(), qt, where("P.x"));
        q.add(eb.momentum.y(), wq.momentum.y(), qt, where("P.y"));
        q.add(eb.l_point, wq.l_point, qt, where("L_point"));
        q.add(eb.l_spin, wq.l_spin, qt, where("L_spin"));
        q.add(eb.t_point, wq.t_point, qt, where("T_point"));
        q.add(eb.t_spin, wq.t_spin, qt, where("T_spin"));
      }
      q.add(energy.messages[m].potential, f.potential, options.quantity_tol,
            [&] { return "step " + std::to_string(steps[m]) + " U"; });
    }
    r.line(st.ok(), "body states of the " + std::to_string(state.size()) +
                        " recorded steps against the reference's free run (absolute tolerance " +
                        g3(options.state_tol) + "): " + st.summary());
    r.line(q.ok(),
           "M, I, P, L_point, L_spin, T_point, T_spin, U of the recorded steps against the reference's "
           "(absolute tolerance " +
               g3(options.quantity_tol) + "): " + q.summary());
  } else if (scene.world.integrator == Integrator::SymplecticEuler && scene.world.winds.empty()) {
    v.rule = "symplectic-energy, " + v.rule;
    if (!match.scene.empty())
      r.info("the scene is FOSSSim's " + match.scene + ", which has no reference output");
    // Symplectic Euler on H = T(P, L) + U(X, theta) (separable: I is constant in 2D) conserves the
    // modified energy E + (dt / 2) Pi up to O(dt^2), Pi being the power of the conservative
    // forces.
    double max_power = 0.0, max_scale = 0.0, err = 0.0, modified = 0.0;
    std::uint64_t worst = 0;
    for (const Terms& t : terms) {
      max_power = std::max(max_power, std::fabs(t.power));
      max_scale = std::max(max_scale, t.scale);
    }
    const double e0 = terms.front().total, m0 = e0 + 0.5 * dt * terms.front().power;
    for (std::size_t m = 0; m < terms.size(); ++m) {
      const double d = std::fabs(terms[m].total - e0);
      if (d > err || std::isnan(d)) {
        err = std::isnan(d) ? HUGE_VAL : d;
        worst = steps[m];
      }
      modified = std::max(modified, std::fabs(terms[m].total + 0.5 * dt * terms[m].power - m0));
    }
    // First order: |E_n - E_0| ~ (dt/2) |Pi_n - Pi_0| <= (dt/2) (max|Pi| + |Pi_0|); the bound is twice
    // that (room for the O(dt^2) remainder), plus rounding.
    const double bound = dt * (max_power + std::fabs(terms.front().power)) + 1e-12 * max_scale;
    v.energy_error = err;
    v.energy_bound = bound;
    r.line(err <= bound,
           "energy conservation (symplectic Euler, gravity and springs): E = T + U recomputed from the "
           "recorded states; max |E - E0| = " +
               g3(err) + " at step " + std::to_string(worst) +
               " <= dt * (max|Pi| + |Pi_0|) + 1e-12 * max(sum |terms|) = " + g3(bound) + " (ratio " +
               g3(bound > 0 ? err / bound : 0.0) + ", E0 = " + g17(e0) + ", max|Pi| = " + g3(max_power) +
               ")");
    r.info("modified energy E + dt/2 Pi drifts by at most " + g3(modified) +
           " (first-order backward error analysis)");
  } else if (!match.scene.empty()) {
    r.info("the scene is FOSSSim's " + match.scene + ", which has no reference output; with " +
           (scene.world.winds.empty() ? "explicit Euler" : "wind") + " energy is not conserved");
  } else {
    r.info(std::string("no FOSSSim reference output") +
           (options.fosssim_dir.empty() ? " (no FOSSSim directory given)" : "") + "; with " +
           (scene.world.winds.empty() ? "explicit Euler" : "wind") + " energy is not conserved");
  }
  v.passed = !r.failed && !v.rule.empty();
  return v;
}

}  // namespace rbsim::check
