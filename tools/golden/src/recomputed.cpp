// The stages on the per-step terms (stages.hpp): every recorded energy term, spring state, pose,
// /tf transform and springs-marker line against its recomputation from the recorded body states.
#include <cmath>

#include "stages.hpp"

namespace rbsim::check {

namespace {

std::string tolerance_text(double rtol) {
  return " (tolerance " + three_digits(rtol) + " x max(1, |value|))";
}

// The orientation quaternion (0, 0, qz, qw) of each body's rotation theta about z.
void quaternions(const State& s, std::vector<double>& qz, std::vector<double>& qw) {
  for (double theta : s.theta) {
    qz.push_back(std::sin(0.5 * theta));
    qw.push_back(std::cos(0.5 * theta));
  }
}

void compare_energy(StepValues& at, const msgs::EnergyTermsMessage& en, const Terms& t, std::size_t gravity) {
  using Body = msgs::EnergyTermsMessage::Body;
  at.each(field(en.bodies, [](const Body& b) { return b.momentum.x(); }), "bodies[].momentum.x", t.px);
  at.each(field(en.bodies, [](const Body& b) { return b.momentum.y(); }), "bodies[].momentum.y", t.py);
  at.each(field(en.bodies, [](const Body& b) { return b.l_point; }), "bodies[].l_point", t.l_point);
  at.each(field(en.bodies, [](const Body& b) { return b.l_spin; }), "bodies[].l_spin", t.l_spin);
  at.each(field(en.bodies, [](const Body& b) { return b.t_point; }), "bodies[].t_point", t.t_point);
  at.each(field(en.bodies, [](const Body& b) { return b.t_spin; }), "bodies[].t_spin", t.t_spin);
  at.each(field(en.forces, [](const msgs::EnergyTermsMessage::Force& f) { return f.potential; }),
          "forces[].potential", t.force_potential);
  at.near(en.momentum.x(), t.momentum_x, "momentum.x");
  at.near(en.momentum.y(), t.momentum_y, "momentum.y");
  at.near(en.angular_momentum, t.angular, "angular_momentum");
  at.near(en.potential, t.potential, "potential");
  at.near(en.kinetic_point, t.kinetic_point, "kinetic_point");
  at.near(en.kinetic_spin, t.kinetic_spin, "kinetic_spin");
  at.near(en.total, t.total, "total");
  if (en.has_split) {  // recordings made before the split of U into gravity and springs lack it
    double u_gravity = 0.0, u_springs = 0.0;
    for (std::size_t i = 0; i < t.force_potential.size(); ++i) {
      (i < gravity ? u_gravity : u_springs) += t.force_potential[i];
    }
    at.near(en.potential_gravity, u_gravity, "potential_gravity");
    at.near(en.potential_spring, u_springs, "potential_spring");
    at.near(en.potential_gravity + en.potential_spring, t.potential, "potential_gravity + potential_spring");
  }
}

void compare_springs(StepValues& at, const msgs::SpringStatesMessage& recorded, const Terms& t,
                     const std::vector<SpringDef>& springs) {
  std::vector<double> ix, iy, jx, jy, length, rest, potential;
  for (std::size_t k = 0; k < t.springs.size(); ++k) {
    ix.push_back(t.springs[k].end_i.x());
    iy.push_back(t.springs[k].end_i.y());
    jx.push_back(t.springs[k].end_j.x());
    jy.push_back(t.springs[k].end_j.y());
    length.push_back(t.springs[k].length);
    rest.push_back(springs[k].rest_length);
    potential.push_back(t.springs[k].potential);
  }
  using Spring = msgs::SpringStatesMessage::Spring;
  const auto& ss = recorded.springs;
  at.each(field(ss, [](const Spring& x) { return x.end_i.x(); }), "springs[].end_i.x", ix);
  at.each(field(ss, [](const Spring& x) { return x.end_i.y(); }), "springs[].end_i.y", iy);
  at.each(field(ss, [](const Spring& x) { return x.end_j.x(); }), "springs[].end_j.x", jx);
  at.each(field(ss, [](const Spring& x) { return x.end_j.y(); }), "springs[].end_j.y", jy);
  at.each(field(ss, [](const Spring& x) { return x.length; }), "springs[].length", length);
  at.each(field(ss, [](const Spring& x) { return x.rest_length; }), "springs[].rest_length", rest);
  at.each(field(ss, [](const Spring& x) { return x.potential; }), "springs[].potential", potential);
}

void compare_transforms(StepValues& at, const msgs::TfMessage& tf, const State& s,
                        const msgs::BodyStatesMessage& states, const std::string& frame_prefix) {
  using T = msgs::TfMessage::Transform;
  const auto& ts = tf.transforms;
  std::vector<double> qz, qw, zero(s.x.size(), 0.0);
  quaternions(s, qz, qw);
  at.each(field(ts, [](const T& x) { return x.x; }), "transforms[].translation.x", s.x);
  at.each(field(ts, [](const T& x) { return x.y; }), "transforms[].translation.y", s.y);
  at.each(field(ts, [](const T& x) { return x.z; }), "transforms[].translation.z", zero);
  at.each(field(ts, [](const T& x) { return x.qx; }), "transforms[].rotation.x", zero);
  at.each(field(ts, [](const T& x) { return x.qy; }), "transforms[].rotation.y", zero);
  at.each(field(ts, [](const T& x) { return x.qz; }), "transforms[].rotation.z", qz);
  at.each(field(ts, [](const T& x) { return x.qw; }), "transforms[].rotation.w", qw);
  const auto& stamp = states.stamp;
  for (std::size_t b = 0; b < ts.size(); ++b) {
    const std::string frame = frame_prefix + "body_" + std::to_string(b);
    if (ts[b].frame_id != "world" || ts[b].child_frame_id != frame || ts[b].stamp.sec != stamp.sec ||
        ts[b].stamp.nanosec != stamp.nanosec) {
      at.tally().fail(at.at() + " transforms[" + std::to_string(b) + "]: " + ts[b].frame_id + " -> " +
                      ts[b].child_frame_id + ", expected world -> " + frame + " at the body states' stamp");
      break;
    }
  }
}

void compare_springs_marker(StepValues& at, const msgs::MarkerMessage& mk, const Terms& t,
                            const msgs::SceneMessage& desc) {
  std::vector<double> px, py, want_x, want_y, rgb, want_rgb;
  for (const Vec2& p : mk.points) {
    px.push_back(p.x());
    py.push_back(p.y());
  }
  for (std::size_t k = 0; k < t.springs.size(); ++k) {
    want_x.insert(want_x.end(), {t.springs[k].end_i.x(), t.springs[k].end_j.x()});
    want_y.insert(want_y.end(), {t.springs[k].end_i.y(), t.springs[k].end_j.y()});
    const Color c = k < desc.spring_colors.size() ? desc.spring_colors[k] : Color{};
    for (int end = 0; end < 2; ++end) want_rgb.insert(want_rgb.end(), {c.r, c.g, c.b});
  }
  for (const auto& c : mk.colors) rgb.insert(rgb.end(), {c[0], c[1], c[2]});
  if (mk.colors.empty()) {  // one colour for every spring: the marker's
    for (std::size_t p = 0; p < mk.points.size(); ++p)
      rgb.insert(rgb.end(), {mk.color[0], mk.color[1], mk.color[2]});
  }
  at.each(px, "points[].x", want_x);
  at.each(py, "points[].y", want_y);
  at.each(rgb, "colors[].rgb", want_rgb);
  if (mk.type != msgs::kMarkerLineList || mk.frame_id != "world") {
    at.tally().fail(at.at() + ": springs marker of type " + std::to_string(mk.type) + " in frame " +
                    mk.frame_id + ", expected a LINE_LIST in world");
  }
}

}  // namespace

void StepValues::near(double got, double want, const char* what, std::size_t index) {
  tally_.add(got, want, rtol_ * std::max(1.0, std::fabs(want)), [&] {
    return at_ + " " + what + (index == kNoIndex ? std::string() : " [" + std::to_string(index) + "]");
  });
}

void StepValues::each(const std::vector<double>& got, const char* path, const std::vector<double>& want) {
  if (got.size() != want.size()) {
    tally_.fail(at_ + " " + path + ": " + std::to_string(got.size()) + " values, expected " +
                std::to_string(want.size()));
    return;
  }
  for (std::size_t i = 0; i < got.size(); ++i) near(got[i], want[i], path, i);
}

namespace {
// The loop every recomputing stage shares: `compare(at, m)` for each recorded step m of `run`,
// within the recompute tolerance, then one report line: `what`, the tolerance and the tally.
template <class Compare>
void verify_each_step(const StageContext& c, const RecordedRun& run, const std::string& what,
                      Compare compare) {
  const double rtol = c.options.recompute_rtol;
  Tally tally;
  for (std::size_t m = 0; m < run.states.size(); ++m) {
    StepValues at(tally, rtol, run.steps[m]);
    compare(at, m);
  }
  c.report.line(tally.ok(), what + tolerance_text(rtol) + ": " + tally.summary());
}
}  // namespace

void verify_energy_terms(const StageContext& c, const RecordedRun& run,
                         const std::vector<msgs::EnergyTermsMessage>& energy) {
  verify_each_step(
      c, run,
      "energy terms: P, L_point, L_spin, T_point, T_spin per body, U per force and the totals of " +
          std::to_string(run.states.size()) + " steps recomputed from the recorded states",
      [&](StepValues& at, std::size_t m) {
        compare_energy(at, energy[m], run.terms[m], c.model.gravity.size());
      });
}

void verify_spring_states(const StageContext& c, const RecordedRun& run,
                          const std::vector<msgs::SpringStatesMessage>& springs) {
  verify_each_step(
      c, run, "spring states: endpoints, lengths and potentials recomputed from the recorded poses",
      [&](StepValues& at, std::size_t m) { compare_springs(at, springs[m], run.terms[m], c.model.springs); });
}

void verify_poses(const StageContext& c, const RecordedRun& run,
                  const std::vector<msgs::PosesMessage>& poses) {
  using Pose = msgs::PosesMessage::Pose;
  verify_each_step(c, run, "poses: positions and orientation quaternions",
                   [&](StepValues& at, std::size_t m) {
                     const State& s = run.states[m];
                     const auto& ps = poses[m].poses;
                     std::vector<double> qz, qw;
                     quaternions(s, qz, qw);
                     at.each(field(ps, [](const Pose& p) { return p.x; }), "poses[].position.x", s.x);
                     at.each(field(ps, [](const Pose& p) { return p.y; }), "poses[].position.y", s.y);
                     at.each(field(ps, [](const Pose& p) { return p.qz; }), "poses[].orientation.z", qz);
                     at.each(field(ps, [](const Pose& p) { return p.qw; }), "poses[].orientation.w", qw);
                   });
}

void verify_tf(const StageContext& c, const RecordedRun& run, const TopicMessages<msgs::TfMessage>& tf,
               const TopicMessages<msgs::BodyStatesMessage>& states) {
  const std::string frame_prefix = body_frame_prefix(states.topic);
  verify_each_step(c, run, "tf: world -> body frame transforms equal to the recorded body states",
                   [&](StepValues& at, std::size_t m) {
                     compare_transforms(at, tf.messages[m], run.states[m], states.messages[m], frame_prefix);
                   });
}

void verify_springs_marker(const StageContext& c, const RecordedRun& run,
                           const std::vector<msgs::MarkerMessage>& marker, const msgs::SceneMessage& desc) {
  verify_each_step(
      c, run, "springs marker: line ends recomputed from the recorded states, scene colours",
      [&](StepValues& at, std::size_t m) { compare_springs_marker(at, marker[m], run.terms[m], desc); });
}

}  // namespace rbsim::check
