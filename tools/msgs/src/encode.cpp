// World snapshot -> CDR messages (the adapters between sim_core and every output).
#include <cmath>

#include "cdr.hpp"
#include "rbsim/msgs.hpp"

namespace rbsim::msgs {

using detail::CdrWriter;

namespace {
constexpr std::string_view kFrame = "world";

void vector2(CdrWriter& w, const Vec2& v) {
  w.f64(v.x());
  w.f64(v.y());
}
void color(CdrWriter& w, const Color& c, float alpha = 1.0f) {
  w.f32(static_cast<float>(c.r));
  w.f32(static_cast<float>(c.g));
  w.f32(static_cast<float>(c.b));
  w.f32(alpha);
}
void point(CdrWriter& w, const Vec2& p) {
  w.f64(p.x());
  w.f64(p.y());
  w.f64(0.0);
}
// geometry_msgs/Pose of a planar body: position (x, y, 0), rotation theta about +z.
void pose(CdrWriter& w, double x, double y, double theta) {
  w.f64(x);
  w.f64(y);
  w.f64(0.0);
  w.f64(0.0);
  w.f64(0.0);
  w.f64(std::sin(0.5 * theta));
  w.f64(std::cos(0.5 * theta));
}
}  // namespace

std::uint64_t sim_time_ns(const World& world) {
  const double ns = std::round(world.time() * 1e9);
  return ns <= 0.0 ? 0 : static_cast<std::uint64_t>(ns);
}

Time sim_time(const World& world) {
  const std::uint64_t ns = sim_time_ns(world);
  return Time{static_cast<std::int32_t>(ns / 1'000'000'000), static_cast<std::uint32_t>(ns % 1'000'000'000)};
}

Encoder::Encoder(const Scene& scene) : scene_(&scene) {}

void Encoder::scene(const World& world, Bytes& out) const {
  const Scene& s = *scene_;
  CdrWriter w(out);
  w.header(sim_time(world), kFrame);
  w.string(s.name);
  w.string(s.description);
  w.string(to_string(world.integrator()));
  w.f64(world.dt());
  w.f64(s.duration);
  w.u64(static_cast<std::uint64_t>(s.step_count()));
  w.sequence_length(static_cast<std::size_t>(world.body_count()));
  for (std::int32_t b = 0; b < world.body_count(); ++b) {
    const BodyId id{b};
    w.f64(world.mass(id));
    w.f64(world.inertia(id));
    w.f64(world.radius(id));
    color(w, s.body_colors[b]);
    const auto hull = world.hull(id);
    w.sequence_length(hull.size());
    for (const Vec2& v : hull) vector2(w, v);
  }
  w.sequence_length(static_cast<std::size_t>(world.spring_count()));
  for (std::int32_t k = 0; k < world.spring_count(); ++k) {
    const SpringDef& sp = world.spring(SpringId{k});
    w.i32(sp.body_i);
    vector2(w, sp.anchor_i);
    w.i32(sp.body_j);
    vector2(w, sp.anchor_j);
    w.f64(sp.stiffness);
    w.f64(sp.rest_length);
    color(w, s.spring_colors[k]);
  }
  w.sequence_length(world.gravity().size());
  for (const GravityDef& g : world.gravity()) vector2(w, g.acceleration);
  w.sequence_length(world.winds().size());
  for (const WindDef& wind : world.winds()) {
    w.f64(wind.beta);
    vector2(w, wind.velocity);
    w.i32(wind.points_per_edge);
  }
  w.boolean(s.viewport.has_value());
  const Viewport vp = s.viewport.value_or(Viewport{});
  w.f64(vp.cx);
  w.f64(vp.cy);
  w.f64(vp.size);
  color(w, s.background);
}

void Encoder::body_states(const World& world, Bytes& out) const {
  CdrWriter w(out);
  w.header(sim_time(world), kFrame);
  w.u64(static_cast<std::uint64_t>(world.step_index()));
  w.sequence_length(static_cast<std::size_t>(world.body_count()));
  for (std::int32_t b = 0; b < world.body_count(); ++b) {
    w.i32(b);
    for (double v :
         {world.x()[b], world.y()[b], world.theta()[b], world.vx()[b], world.vy()[b], world.omega()[b]}) {
      w.f64(v);
    }
  }
}

void Encoder::spring_states(const World& world, Bytes& out) const {
  CdrWriter w(out);
  w.header(sim_time(world), kFrame);
  w.u64(static_cast<std::uint64_t>(world.step_index()));
  w.sequence_length(static_cast<std::size_t>(world.spring_count()));
  for (std::int32_t k = 0; k < world.spring_count(); ++k) {
    const SpringState st = world.spring_state(SpringId{k});
    w.i32(k);
    vector2(w, st.end_i);
    vector2(w, st.end_j);
    w.f64(st.length);
    w.f64(world.spring(SpringId{k}).rest_length);
    w.f64(st.potential);
  }
}

void Encoder::energy(const World& world, Bytes& out) const {
  CdrWriter w(out);
  w.header(sim_time(world), kFrame);
  w.u64(static_cast<std::uint64_t>(world.step_index()));
  double t_point = 0.0, t_spin = 0.0;
  w.sequence_length(static_cast<std::size_t>(world.body_count()));
  for (std::int32_t b = 0; b < world.body_count(); ++b) {
    const BodyQuantities q = world.quantities(BodyId{b});
    w.i32(b);
    vector2(w, q.momentum);
    w.f64(q.l_point);
    w.f64(q.l_spin);
    w.f64(q.t_point);
    w.f64(q.t_spin);
    t_point += q.t_point;
    t_spin += q.t_spin;
  }
  // Per force: each gravity field's U = -sum_b M_b g . X_b, then each spring's.
  w.sequence_length(world.gravity().size() + static_cast<std::size_t>(world.spring_count()));
  double potential = 0.0;
  for (std::size_t g = 0; g < world.gravity().size(); ++g) {
    const Vec2 acc = world.gravity()[g].acceleration;
    double u = 0.0;
    for (std::int32_t b = 0; b < world.body_count(); ++b) {
      u -= world.mass(BodyId{b}) * (acc.x() * world.x()[b] + acc.y() * world.y()[b]);
    }
    w.u8(0);
    w.i32(static_cast<std::int32_t>(g));
    w.f64(u);
    potential += u;
  }
  for (std::int32_t k = 0; k < world.spring_count(); ++k) {
    const double u = world.spring_state(SpringId{k}).potential;
    w.u8(1);
    w.i32(k);
    w.f64(u);
    potential += u;
  }
  const SceneTotals totals = world.totals();
  vector2(w, totals.momentum);
  w.f64(totals.angular);
  w.f64(potential);
  w.f64(t_point);
  w.f64(t_spin);
  w.f64(potential + t_point + t_spin);
}

void Encoder::poses(const World& world, Bytes& out) const {
  CdrWriter w(out);
  w.header(sim_time(world), kFrame);
  w.sequence_length(static_cast<std::size_t>(world.body_count()));
  for (std::int32_t b = 0; b < world.body_count(); ++b) pose(w, world.x()[b], world.y()[b], world.theta()[b]);
}

// One LINE_STRIP per body (its closed hull outline, in the body's frame via the marker pose)
// and one LINE_LIST holding every spring, coloured per spring.
void Encoder::markers(const World& world, Bytes& out) const {
  const Scene& s = *scene_;
  const Time stamp = sim_time(world);
  CdrWriter w(out);
  const std::size_t count = static_cast<std::size_t>(world.body_count()) + (world.spring_count() > 0 ? 1 : 0);
  w.sequence_length(count);
  auto marker_head = [&](std::string_view ns, std::int32_t id, std::int32_t type) {
    w.header(stamp, kFrame);
    w.string(ns);
    w.i32(id);
    w.i32(type);
    w.i32(0);  // ADD
  };
  auto marker_tail = [&] {
    w.i32(0);  // lifetime: forever
    w.u32(0);
    w.boolean(false);  // frame_locked
  };
  auto marker_rest = [&] {
    w.string("");          // texture_resource
    w.header(Time{}, "");  // texture: sensor_msgs/CompressedImage
    w.string("");
    w.sequence_length(0);
    w.sequence_length(0);  // uv_coordinates
    w.string("");          // text
    w.string("");          // mesh_resource
    w.string("");          // mesh_file.filename
    w.sequence_length(0);  // mesh_file.data
    w.boolean(false);      // mesh_use_embedded_materials
  };
  for (std::int32_t b = 0; b < world.body_count(); ++b) {
    const BodyId id{b};
    marker_head("bodies", b, 4);  // LINE_STRIP
    pose(w, world.x()[b], world.y()[b], world.theta()[b]);
    const double width = 2.0 * world.radius(id);
    w.f64(width);  // scale.x = line width
    w.f64(0.0);
    w.f64(0.0);
    color(w, s.body_colors[b]);
    marker_tail();
    const auto hull = world.hull(id);
    w.sequence_length(hull.size() + 1);
    for (const Vec2& v : hull) point(w, v);
    point(w, hull.front());
    w.sequence_length(0);  // colors
    marker_rest();
  }
  if (world.spring_count() > 0) {
    marker_head("springs", 0, 5);  // LINE_LIST
    pose(w, 0.0, 0.0, 0.0);
    w.f64(0.05);
    w.f64(0.0);
    w.f64(0.0);
    color(w, Color{0.25, 0.25, 0.25});
    marker_tail();
    w.sequence_length(2 * static_cast<std::size_t>(world.spring_count()));
    for (std::int32_t k = 0; k < world.spring_count(); ++k) {
      const SpringState st = world.spring_state(SpringId{k});
      point(w, st.end_i);
      point(w, st.end_j);
    }
    w.sequence_length(2 * static_cast<std::size_t>(world.spring_count()));
    for (std::int32_t k = 0; k < world.spring_count(); ++k) {
      color(w, s.spring_colors[k]);
      color(w, s.spring_colors[k]);
    }
    marker_rest();
  }
}

void Encoder::clock(const World& world, Bytes& out) const {
  CdrWriter w(out);
  w.time(sim_time(world));
}

void Encoder::encode(TopicId id, const World& world, Bytes& out) const {
  switch (id) {
    case TopicId::Scene:
      return scene(world, out);
    case TopicId::BodyStates:
      return body_states(world, out);
    case TopicId::SpringStates:
      return spring_states(world, out);
    case TopicId::Energy:
      return energy(world, out);
    case TopicId::Poses:
      return poses(world, out);
    case TopicId::Markers:
      return markers(world, out);
    case TopicId::Clock:
      return clock(world, out);
  }
}

}  // namespace rbsim::msgs
