// World snapshot -> CDR messages (the adapters between sim_core and every output).
#include <algorithm>
#include <cmath>
#include <numeric>

#include "cdr.hpp"
#include "rbsim/assert.hpp"
#include "rbsim/msgs.hpp"
#include "rbsim/time.hpp"

namespace rbsim::msgs {

using detail::CdrWriter;

namespace {
constexpr std::string_view kFrame = "world";
// Springs are drawn as lines of this width (m) and their fixed anchors as spheres of this
// diameter: scene units are metres and bodies are of the order of 0.1-1 m.
constexpr double kSpringWidth = 0.05, kAnchorSize = 0.15;
const Color kSpringGrey{0.25, 0.25, 0.25};

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
void quaternion(CdrWriter& w, double theta) {
  const Quaternion q = quaternion_z(theta);
  w.f64(q.x);
  w.f64(q.y);
  w.f64(q.z);
  w.f64(q.w);
}
// geometry_msgs/Pose of a planar body: position (x, y, 0), rotation theta about +z.
void pose(CdrWriter& w, double x, double y, double theta) {
  w.f64(x);
  w.f64(y);
  w.f64(0.0);
  quaternion(w, theta);
}

// The fields of a visualization_msgs/Marker up to its points (action ADD unless said, identity
// pose, lifetime 0 = forever).
struct MarkerHead {
  Time stamp;
  std::string_view frame, ns;
  std::int32_t id = 0, type = 0;
  double sx = 1.0, sy = 1.0, sz = 1.0;  // scale: line width in x for lines, diameter for spheres
  Color color;
  bool frame_locked = false;
  std::int32_t action = 0;  // ADD
};
constexpr std::int32_t kMarkerDeleteAll = 3;
void marker_head(CdrWriter& w, const MarkerHead& m) {
  w.header(m.stamp, m.frame);
  w.string(m.ns);
  w.i32(m.id);
  w.i32(m.type);
  w.i32(m.action);
  pose(w, 0.0, 0.0, 0.0);
  w.f64(m.sx);
  w.f64(m.sy);
  w.f64(m.sz);
  color(w, m.color);
  w.i32(0);  // lifetime: forever
  w.u32(0);
  w.boolean(m.frame_locked);
}
// The fields after the colours, all empty: no texture, text or mesh.
void marker_rest(CdrWriter& w) {
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
}

double cross(const Vec2& a, const Vec2& b) {
  return a.x() * b.y() - a.y() * b.x();
}
}  // namespace

Quaternion quaternion_z(double theta) {
  return Quaternion{0.0, 0.0, std::sin(0.5 * theta), std::cos(0.5 * theta)};
}

std::string body_frame(std::string_view ns, std::string_view name) {
  while (ns.starts_with('/')) ns.remove_prefix(1);
  while (ns.ends_with('/')) ns.remove_suffix(1);
  return (ns.empty() ? std::string() : std::string(ns) + "/") + std::string(name);
}

std::string body_frame(std::string_view ns, std::int32_t index) {
  return body_frame(ns, scene_body_name(index));
}

// Ear clipping on the counter-clockwise vertex order: cut off a convex corner whose triangle
// holds no other vertex, until a triangle is left. A simple polygon always has such an ear.
std::vector<std::uint32_t> triangulate(std::span<const Vec2> p) {
  std::vector<std::uint32_t> out;
  const std::size_t n = p.size();
  if (n < 3) return out;
  double area2 = 0.0;
  for (std::size_t i = 0; i < n; ++i) area2 += cross(p[i], p[(i + 1) % n]);
  std::vector<std::uint32_t> v(n);
  std::iota(v.begin(), v.end(), 0u);
  if (area2 < 0.0) std::reverse(v.begin(), v.end());
  const auto turn = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    return cross(p[b] - p[a], p[c] - p[a]);
  };
  // Inside or on the border of the CCW triangle abc (a vertex on a diagonal blocks it too).
  const auto within = [&](const Vec2& q, std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    return cross(p[b] - p[a], q - p[a]) >= 0.0 && cross(p[c] - p[b], q - p[b]) >= 0.0 &&
           cross(p[a] - p[c], q - p[c]) >= 0.0;
  };
  while (v.size() > 3) {
    const std::size_t m = v.size();
    bool clipped = false;
    for (std::size_t i = 0; i < m && !clipped; ++i) {
      const std::uint32_t a = v[(i + m - 1) % m], b = v[i], c = v[(i + 1) % m];
      if (turn(a, b, c) <= 0.0) continue;  // reflex or straight: not an ear
      bool ear = true;
      for (const std::uint32_t k : v) {
        if (k == a || k == b || k == c || p[k] == p[a] || p[k] == p[b] || p[k] == p[c]) continue;
        if (within(p[k], a, b, c)) {
          ear = false;
          break;
        }
      }
      if (!ear) continue;
      out.insert(out.end(), {a, b, c});
      v.erase(v.begin() + static_cast<std::ptrdiff_t>(i));
      clipped = true;
    }
    if (clipped) continue;
    // No ear: drop a straight vertex (it adds no area), else (not a simple polygon) fan the rest.
    bool dropped = false;
    for (std::size_t i = 0; i < m && !dropped; ++i) {
      if (turn(v[(i + m - 1) % m], v[i], v[(i + 1) % m]) == 0.0) {
        v.erase(v.begin() + static_cast<std::ptrdiff_t>(i));
        dropped = true;
      }
    }
    if (dropped) continue;
    for (std::size_t i = 1; i + 1 < m; ++i) out.insert(out.end(), {v[0], v[i], v[i + 1]});
    return out;
  }
  if (turn(v[0], v[1], v[2]) > 0.0) out.insert(out.end(), {v[0], v[1], v[2]});
  return out;
}

std::uint64_t sim_time_ns(std::int64_t step, double dt) {
  return static_cast<std::uint64_t>(seconds_to_ns_clamped(static_cast<double>(step) * dt));
}

std::uint64_t sim_time_ns(const World& world) {
  return sim_time_ns(world.step_index(), world.dt());
}

Time time_from_ns(std::uint64_t ns) {
  return Time{static_cast<std::int32_t>(ns / 1'000'000'000), static_cast<std::uint32_t>(ns % 1'000'000'000)};
}

Time sim_time(std::int64_t step, double dt) {
  return time_from_ns(sim_time_ns(step, dt));
}

Time sim_time(const World& world) {
  return sim_time(world.step_index(), world.dt());
}

Encoder::Encoder(const Scene& scene, std::string_view ns) : scene_(&scene), ns_(ns) {
  restructure(entities_of(scene));
}

void Encoder::restructure(const Entities& entities) {
  if (entities.scene != nullptr) scene_ = entities.scene;  // a world loaded: its own name, forces, ...
  // The frames of the bodies named as before, up to the first change, stay (a spawn appends one).
  const auto& old = entities_.body_names;
  const auto& now = entities.body_names;
  const auto same = std::mismatch(old.begin(), old.end(), now.begin(), now.end()).first - old.begin();
  frames_.resize(static_cast<std::size_t>(same));
  for (auto k = static_cast<std::size_t>(same); k < now.size(); ++k)
    frames_.push_back(body_frame(ns_, now[k]));
  entities_ = entities;
  const auto& colors = entities.spring_colors;
  spring_color_.reset();
  if (!colors.empty() &&
      std::all_of(colors.begin(), colors.end(), [&](const Color& c) { return c == colors.front(); })) {
    spring_color_ = colors.front();
  }
}

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
    color(w, entities_.body_colors[b]);
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
    color(w, entities_.spring_colors[k]);
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
    w.i32(world.body_id(BodyId{b}));
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
    w.i32(world.spring_id(SpringId{k}));
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
    w.i32(world.body_id(BodyId{b}));
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
    w.i32(world.spring_id(SpringId{k}));
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
  // The split as the world sums it, so readers (log export) need not re-add the per-force terms,
  // whose sum associates differently and, for several gravity fields, depends on FMA contraction.
  const Energy e = world.energy();
  w.f64(e.u_gravity);
  w.f64(e.u_spring);
}

void Encoder::poses(const World& world, Bytes& out) const {
  CdrWriter w(out);
  w.header(sim_time(world), kFrame);
  w.sequence_length(static_cast<std::size_t>(world.body_count()));
  for (std::int32_t b = 0; b < world.body_count(); ++b) pose(w, world.x()[b], world.y()[b], world.theta()[b]);
}

void Encoder::tf(const World& world, Bytes& out) const {
  const Time stamp = sim_time(world);
  CdrWriter w(out);
  w.sequence_length(static_cast<std::size_t>(world.body_count()));
  for (std::int32_t b = 0; b < world.body_count(); ++b) {
    w.header(stamp, kFrame);
    w.string(frames_[static_cast<std::size_t>(b)]);
    pose(w, world.x()[b], world.y()[b], world.theta()[b]);  // Transform: translation, rotation
  }
}

// One LINE_LIST holding every spring in world coordinates, coloured per spring. When every spring
// has the same colour, it is the marker's `color` and `colors` is empty (viewers then draw every
// vertex in `color`): 32 bytes less per spring and step.
void Encoder::springs(const World& world, Bytes& out) const {
  CdrWriter w(out);
  marker_head(w, {sim_time(world), kFrame, "springs", 0, kMarkerLineList, kSpringWidth, 0.0, 0.0,
                  spring_color_.value_or(kSpringGrey), false});
  const std::size_t n = static_cast<std::size_t>(world.spring_count());
  w.sequence_length(2 * n);
  for (std::int32_t k = 0; k < world.spring_count(); ++k) {
    const SpringState st = world.spring_state(SpringId{k});
    point(w, st.end_i);
    point(w, st.end_j);
  }
  w.sequence_length(spring_color_ ? 0 : 2 * n);
  for (std::int32_t k = 0; !spring_color_ && k < world.spring_count(); ++k) {
    color(w, entities_.spring_colors[k]);
    color(w, entities_.spring_colors[k]);
  }
  marker_rest(w);
}

// Per body, in its own frame (frame_locked: it moves with /tf): the hull filled (TRIANGLE_LIST,
// ear-clipped so concave shapes fill right) and its closed outline (LINE_STRIP) of width 2 r in
// the same colour, which together cover the hull grown by the radius r as tools/render draws it.
// Then one SPHERE_LIST in "world" marking the springs' fixed anchors, in the springs' colours.
void Encoder::markers(const World& world, Bytes& out) const {
  const Time stamp = sim_time(world);
  std::vector<Vec2> anchors;
  std::vector<Color> anchor_colors;
  for (std::int32_t k = 0; k < world.spring_count(); ++k) {
    const SpringDef& sp = world.spring(SpringId{k});
    for (const auto& [body, anchor] :
         {std::pair{sp.body_i, sp.anchor_i}, std::pair{sp.body_j, sp.anchor_j}}) {
      if (body != kFixed) continue;
      anchors.push_back(anchor);
      anchor_colors.push_back(entities_.spring_colors[k]);
    }
  }
  CdrWriter w(out);
  // After a change the array starts with a DELETEALL (action 3), which drops every marker a viewer
  // holds from this topic before the world's markers as they now stand.
  const bool delete_all = entities_.epoch > 0;
  w.sequence_length((delete_all ? 1 : 0) + 2 * static_cast<std::size_t>(world.body_count()) +
                    (anchors.empty() ? 0 : 1));
  if (delete_all) {
    marker_head(
        w, {stamp, kFrame, "", 0, kMarkerLineStrip, 1.0, 1.0, 1.0, kSpringGrey, false, kMarkerDeleteAll});
    w.sequence_length(0);
    w.sequence_length(0);
    marker_rest(w);
  }
  std::vector<std::uint32_t> triangles;
  std::span<const Vec2> triangulated;  // the hull `triangles` cut: bodies sharing a shape share it
  for (std::int32_t b = 0; b < world.body_count(); ++b) {
    const BodyId id{b};
    const std::int32_t marker = world.body_id(id);  // a body keeps its markers' ids across changes
    const std::string& frame = frames_[static_cast<std::size_t>(b)];
    const auto hull = world.hull(id);
    const Color c = entities_.body_colors[b];
    marker_head(w, {stamp, frame, "hulls", marker, kMarkerTriangleList, 1.0, 1.0, 1.0, c, true});
    if (hull.data() != triangulated.data() || hull.size() != triangulated.size()) {
      triangles = triangulate(hull);
      triangulated = hull;
    }
    w.sequence_length(triangles.size());
    for (const std::uint32_t i : triangles) point(w, hull[i]);
    w.sequence_length(0);  // colors: the marker's
    marker_rest(w);
    marker_head(
        w, {stamp, frame, "outlines", marker, kMarkerLineStrip, 2.0 * world.radius(id), 0.0, 0.0, c, true});
    w.sequence_length(hull.size() + 1);
    for (const Vec2& v : hull) point(w, v);
    point(w, hull.front());
    w.sequence_length(0);
    marker_rest(w);
  }
  if (!anchors.empty()) {
    marker_head(w, {stamp, kFrame, "anchors", 0, kMarkerSphereList, kAnchorSize, kAnchorSize, kAnchorSize,
                    kSpringGrey, false});
    w.sequence_length(anchors.size());
    for (const Vec2& a : anchors) point(w, a);
    w.sequence_length(anchor_colors.size());
    for (const Color& c : anchor_colors) color(w, c);
    marker_rest(w);
  }
}

const Bytes& encode_clock(std::uint64_t t_ns, Bytes& out) {
  {
    CdrWriter w(out);
    w.time(time_from_ns(t_ns));
  }  // finished: padded
  return out;
}

void Encoder::clock(const World& world, Bytes& out) const {
  encode_clock(sim_time_ns(world), out);
}

void Encoder::encode(TopicId id, const World& world, Bytes& out) const {
  switch (id) {
    case TopicId::SceneDescription:
      return scene(world, out);
    case TopicId::BodyStates:
      return body_states(world, out);
    case TopicId::SpringStates:
      return spring_states(world, out);
    case TopicId::Energy:
      return energy(world, out);
    case TopicId::Poses:
      return poses(world, out);
    case TopicId::Tf:
      return tf(world, out);
    case TopicId::Springs:
      return springs(world, out);
    case TopicId::Markers:
      return markers(world, out);
    case TopicId::Clock:
      return clock(world, out);
    case TopicId::Commands:
      break;  // an event topic: the controller's, never encoded from a World
  }
  RBSIM_ASSERT(false, "Encoder::encode: not a topic of the world");
}

StepMessages::StepMessages(const Scene& scene, std::string_view ns) : encoder_(scene, ns) {
  step_.fill(-1);
}

const Bytes& StepMessages::get(TopicId id, const World& world) {
  const auto i = static_cast<std::size_t>(id);
  if (world_[i] != &world || step_[i] != world.step_index()) {
    encoder_.encode(id, world, bytes_[i]);
    world_[i] = &world;
    step_[i] = world.step_index();
  }
  return bytes_[i];
}

void StepMessages::restructure(const Entities& entities) {
  if (entities.epoch == epoch_) return;  // a second sink told of the change this step
  epoch_ = entities.epoch;
  encoder_.restructure(entities);
  step_.fill(-1);
}

}  // namespace rbsim::msgs
