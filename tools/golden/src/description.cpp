// The stages on what a golden states about its scene and its steps (stages.hpp): the scene
// description against the scene file, the recorded steps, stamps and initial state.
#include <algorithm>
#include <cmath>

#include "stages.hpp"

namespace rbsim::check {

namespace {

// The scene description's comparisons: counts, integers and inputs exactly, recomputed values
// (mass, inertia, hull) to 1e-12 relative.
class DescriptionTally {
 public:
  void exact(double got, double want, const std::string& what) {
    tally.add(got, want, 0.0, [&] { return what; });
  }
  void relative(double got, double want, const std::string& what) {
    tally.add(got, want, 1e-12 * std::max(1.0, std::fabs(want)), [&] { return what; });
  }
  // Colours travel as float32 (std_msgs/ColorRGBA): the scene's, rounded so, exactly.
  void colour(const Color& got, const Color& want, const std::string& id) {
    exact(got.r, static_cast<float>(want.r), id + " colour r");
    exact(got.g, static_cast<float>(want.g), id + " colour g");
    exact(got.b, static_cast<float>(want.b), id + " colour b");
  }
  Tally tally;
};

void compare_bodies(const msgs::SceneMessage& desc, const Model& model, DescriptionTally& t) {
  using Body = msgs::SceneMessage::Body;
  const std::size_t bodies = model.mass.size();
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
  t.exact(static_cast<double>(mass.size()), static_cast<double>(bodies), "body count");
  std::size_t h = 0;  // the flattened hulls' index: a body with too few vertices shifts the rest
  for (std::size_t b = 0; b < std::min(bodies, mass.size()); ++b) {
    const std::string id = "body " + std::to_string(b);
    t.relative(mass[b], model.mass[b], id + " mass");
    t.relative(inertia[b], model.inertia[b], id + " inertia");
    t.exact(hull_n[b], static_cast<double>(model.body_hull[b].size()), id + " hull vertex count");
    for (std::size_t k = 0; k < model.body_hull[b].size() && h < hx.size(); ++k, ++h) {
      const Vec2& want = model.body_hull[b][k];
      t.relative(hx[h], want.x(), id + " hull vertex " + std::to_string(k) + " x");
      t.relative(hy[h], want.y(), id + " hull vertex " + std::to_string(k) + " y");
    }
  }
}

void compare_springs(const msgs::SceneMessage& desc, const Model& model, DescriptionTally& t) {
  const auto& ds = desc.springs;
  const auto body_i = field(ds, [](const SpringDef& d) { return d.body_i; });
  const auto body_j = field(ds, [](const SpringDef& d) { return d.body_j; });
  const auto anchor_ix = field(ds, [](const SpringDef& d) { return d.anchor_i.x(); });
  const auto anchor_iy = field(ds, [](const SpringDef& d) { return d.anchor_i.y(); });
  const auto anchor_jx = field(ds, [](const SpringDef& d) { return d.anchor_j.x(); });
  const auto anchor_jy = field(ds, [](const SpringDef& d) { return d.anchor_j.y(); });
  const auto stiffness = field(ds, [](const SpringDef& d) { return d.stiffness; });
  const auto rest_length = field(ds, [](const SpringDef& d) { return d.rest_length; });
  t.exact(static_cast<double>(stiffness.size()), static_cast<double>(model.springs.size()), "spring count");
  for (std::size_t s = 0; s < std::min(stiffness.size(), model.springs.size()); ++s) {
    const SpringDef& sp = model.springs[s];
    const std::string id = "spring " + std::to_string(s);
    t.exact(body_i[s], sp.body_i, id + " body_i");
    t.exact(body_j[s], sp.body_j, id + " body_j");
    t.exact(anchor_ix[s], sp.anchor_i.x(), id + " anchor_i.x");
    t.exact(anchor_iy[s], sp.anchor_i.y(), id + " anchor_i.y");
    t.exact(anchor_jx[s], sp.anchor_j.x(), id + " anchor_j.x");
    t.exact(anchor_jy[s], sp.anchor_j.y(), id + " anchor_j.y");
    t.exact(stiffness[s], sp.stiffness, id + " stiffness");
    t.exact(rest_length[s], sp.rest_length, id + " rest_length");
  }
}

void compare_forces(const msgs::SceneMessage& desc, const Scene& scene, const Model& model,
                    DescriptionTally& t) {
  const auto gx = field(desc.gravity, [](const GravityDef& d) { return d.acceleration.x(); });
  const auto gy = field(desc.gravity, [](const GravityDef& d) { return d.acceleration.y(); });
  t.exact(static_cast<double>(gx.size()), static_cast<double>(model.gravity.size()), "gravity count");
  for (std::size_t g = 0; g < std::min(gx.size(), model.gravity.size()); ++g) {
    t.exact(gx[g], model.gravity[g].acceleration.x(), "gravity " + std::to_string(g) + " x");
    t.exact(gy[g], model.gravity[g].acceleration.y(), "gravity " + std::to_string(g) + " y");
  }
  const auto beta = field(desc.winds, [](const WindDef& d) { return d.beta; });
  const auto wx = field(desc.winds, [](const WindDef& d) { return d.velocity.x(); });
  const auto wy = field(desc.winds, [](const WindDef& d) { return d.velocity.y(); });
  const auto points = field(desc.winds, [](const WindDef& d) { return d.points_per_edge; });
  t.exact(static_cast<double>(beta.size()), static_cast<double>(scene.world.winds.size()), "wind count");
  for (std::size_t w = 0; w < std::min(beta.size(), scene.world.winds.size()); ++w) {
    const WindDef& wd = scene.world.winds[w];
    t.exact(beta[w], wd.beta, "wind " + std::to_string(w) + " beta");
    t.exact(wx[w], wd.velocity.x(), "wind " + std::to_string(w) + " velocity.x");
    t.exact(wy[w], wd.velocity.y(), "wind " + std::to_string(w) + " velocity.y");
    t.exact(points[w], wd.points_per_edge, "wind " + std::to_string(w) + " points_per_edge");
  }
}

std::uint64_t stamp_ns(std::uint64_t step, double dt) {
  const double ns = std::round(static_cast<double>(step) * dt * 1e9);
  return ns <= 0.0 ? 0 : static_cast<std::uint64_t>(ns);
}

// The body states of every message, as far as each holds one state per body with ids in order.
RecordedRun states_of(const std::vector<msgs::BodyStatesMessage>& messages, std::size_t bodies,
                      Tally& tally) {
  using Body = msgs::BodyStatesMessage::Body;
  RecordedRun run;
  for (std::size_t m = 0; m < messages.size(); ++m) {
    const msgs::BodyStatesMessage& msg = messages[m];
    State s;
    s.x = field(msg.bodies, [](const Body& b) { return b.state.position.x(); });
    s.y = field(msg.bodies, [](const Body& b) { return b.state.position.y(); });
    s.theta = field(msg.bodies, [](const Body& b) { return b.state.theta; });
    s.vx = field(msg.bodies, [](const Body& b) { return b.state.velocity.x(); });
    s.vy = field(msg.bodies, [](const Body& b) { return b.state.velocity.y(); });
    s.omega = field(msg.bodies, [](const Body& b) { return b.state.omega; });
    const auto ids = field(msg.bodies, [](const Body& b) { return b.id; });
    if (s.x.size() != bodies || s.omega.size() != bodies || ids.size() != bodies) {
      tally.fail("step message " + std::to_string(m) + " holds " + std::to_string(s.x.size()) + " bodies");
      break;
    }
    for (std::size_t b = 0; b < bodies; ++b) {
      if (ids[b] != static_cast<double>(b))
        tally.fail("message " + std::to_string(m) + " body ids out of order");
    }
    run.steps.push_back(msg.step);
    run.states.push_back(std::move(s));
  }
  return run;
}

// Steps 0, K, 2K, ... stamped step * dt in log time and header, up to the scene's last step.
void check_steps_and_stamps(const StageContext& c, const TopicMessages<msgs::BodyStatesMessage>& states,
                            const std::vector<std::uint64_t>& steps, Tally& tally) {
  const std::uint64_t K = steps.size() >= 2 ? steps[1] - steps[0] : 1;
  const auto scene_steps = static_cast<std::uint64_t>(c.verification().steps);
  if (steps.empty() || steps[0] != 0) tally.fail("the first recorded step is not step 0");
  for (std::size_t m = 0; m < steps.size(); ++m) {
    if (steps[m] != m * K) {
      tally.fail("recorded step " + std::to_string(steps[m]) + " where step " + std::to_string(m * K) +
                 " was expected");
      break;
    }
    const std::uint64_t ns = stamp_ns(steps[m], c.scene.world.dt);
    tally.add(static_cast<double>(states.log_time[m]), static_cast<double>(ns), 0.0,
              [&] { return "step " + std::to_string(steps[m]) + " log time"; });
    const double sec = states.messages[m].stamp.sec, nsec = states.messages[m].stamp.nanosec;
    tally.add(sec * 1e9 + nsec, static_cast<double>(ns), 0.0,
              [&] { return "step " + std::to_string(steps[m]) + " header stamp"; });
  }
  if (c.options.whole_run && !steps.empty() &&
      (steps.back() > scene_steps || scene_steps - steps.back() >= std::max<std::uint64_t>(K, 1))) {
    tally.fail("the recording ends at step " + std::to_string(steps.back()) + ", the scene runs " +
               std::to_string(scene_steps) + " steps");
  }
}

// The other per-step topics: as many messages as body states, at their log times, of their steps
// (poses, /tf and the springs marker carry no step).
void check_other_topics(const GoldenLog& log, const std::vector<std::uint64_t>& steps, Tally& tally) {
  struct Other {
    const std::string& topic;
    const std::vector<mcap::Timestamp>& log_time;
    std::vector<std::uint64_t> steps;
  };
  std::vector<Other> others = {{log.springs.topic, log.springs.log_time, {}},
                               {log.energy.topic, log.energy.log_time, {}}};
  for (const auto& msg : log.springs.messages) others[0].steps.push_back(msg.step);
  for (const auto& msg : log.energy.messages) others[1].steps.push_back(msg.step);
  if (!log.poses.messages.empty()) others.push_back({log.poses.topic, log.poses.log_time, {}});
  if (!log.tf.messages.empty()) others.push_back({log.tf.topic, log.tf.log_time, {}});
  if (!log.springs_marker.messages.empty())
    others.push_back({log.springs_marker.topic, log.springs_marker.log_time, {}});
  const auto& states = log.states;
  for (const Other& t : others) {
    if (t.log_time.size() != states.messages.size()) {
      tally.fail(t.topic + " has " + std::to_string(t.log_time.size()) + " messages, " + states.topic + " " +
                 std::to_string(states.messages.size()));
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
}

// Step 0 is the scene's initial state: bodies at their centres of mass, unrotated, at the
// scene's velocities.
void check_initial_state(const StageContext& c, const State& s0, Tally& tally) {
  for (std::size_t b = 0; b < c.model.mass.size(); ++b) {
    const BodyDef& def = c.scene.world.bodies[b];
    const Vec2& center = c.model.center[b];
    const std::string id = "step 0 body " + std::to_string(b);
    const double tol = 1e-12 * std::max(1.0, center.norm());
    tally.add(s0.x[b], center.x(), tol, [&] { return id + " x"; });
    tally.add(s0.y[b], center.y(), tol, [&] { return id + " y"; });
    tally.add(s0.theta[b], 0.0, 0.0, [&] { return id + " theta"; });
    tally.add(s0.vx[b], def.velocity.x(), 0.0, [&] { return id + " vx"; });
    tally.add(s0.vy[b], def.velocity.y(), 0.0, [&] { return id + " vy"; });
    tally.add(s0.omega[b], def.omega, 0.0, [&] { return id + " omega"; });
  }
}

}  // namespace

std::string body_frame_prefix(const std::string& states_topic) {
  std::string ns = states_topic.substr(0, states_topic.rfind('/'));
  if (!ns.empty()) ns.erase(0, 1);  // the leading '/'
  return ns.empty() ? ns : ns + "/";
}

bool verify_scene_description(const StageContext& c, const LatchedScene& latched) {
  const msgs::SceneMessage& desc = *latched.description;
  const Scene& scene = c.scene;
  const std::int64_t steps = c.verification().steps;
  DescriptionTally t;
  if (latched.messages != 1 || latched.log_time != 0) {
    t.tally.fail("expected one scene description at log time 0, found " + std::to_string(latched.messages));
  }
  if (desc.integrator != to_string(scene.world.integrator)) {
    t.tally.fail("integrator '" + desc.integrator + "', scene " + to_string(scene.world.integrator));
  }
  t.exact(desc.dt, scene.world.dt, "dt");
  t.exact(desc.duration, scene.duration, "duration");
  t.exact(static_cast<double>(desc.step_count), static_cast<double>(steps), "step_count");
  compare_bodies(desc, c.model, t);
  compare_springs(desc, c.model, t);
  for (std::size_t b = 0; b < std::min(desc.bodies.size(), scene.body_colors.size()); ++b)
    t.colour(desc.bodies[b].color, scene.body_colors[b], "body " + std::to_string(b));
  for (std::size_t s = 0; s < std::min(desc.spring_colors.size(), scene.spring_colors.size()); ++s)
    t.colour(desc.spring_colors[s], scene.spring_colors[s], "spring " + std::to_string(s));
  compare_forces(desc, scene, c.model, t);
  c.report.line(t.tally.ok(), "scene description: " + std::to_string(c.model.mass.size()) +
                                  " bodies (M, I and body-space hulls recomputed "
                                  "from the vertices), " +
                                  std::to_string(c.model.springs.size()) + " springs, colours, " +
                                  std::to_string(c.model.gravity.size()) + " gravity, " +
                                  std::to_string(scene.world.winds.size()) + " wind, dt " +
                                  full_precision(scene.world.dt) + ", " + to_string(scene.world.integrator) +
                                  ", " + std::to_string(steps) + " steps: " + t.tally.summary());
  // With other counts the recording cannot be read against this scene; with other values it can,
  // and the later stages show what they break.
  return desc.bodies.size() == c.model.mass.size() && desc.springs.size() == c.model.springs.size() &&
         desc.gravity.size() == c.model.gravity.size();
}

std::optional<RecordedRun> verify_recorded_steps(const StageContext& c, const GoldenLog& log) {
  Tally tally;
  RecordedRun run = states_of(log.states.messages, c.model.mass.size(), tally);
  const std::vector<std::uint64_t>& steps = run.steps;
  const std::uint64_t K = steps.size() >= 2 ? steps[1] - steps[0] : 1;
  GoldenVerification& v = c.verification();
  v.record_every = static_cast<std::int64_t>(K);
  v.last_step = steps.empty() ? 0 : static_cast<std::int64_t>(steps.back());
  check_steps_and_stamps(c, log.states, steps, tally);
  check_other_topics(log, steps, tally);
  if (!run.states.empty()) check_initial_state(c, run.states[0], tally);
  c.report.line(tally.ok(), "recording: steps 0.." + std::to_string(v.last_step) + " every " +
                                std::to_string(K) + " (" + std::to_string(steps.size()) +
                                " per topic), stamps = step * dt, initial state = scene: " + tally.summary());
  if (!tally.ok()) return std::nullopt;
  return run;
}

}  // namespace rbsim::check
