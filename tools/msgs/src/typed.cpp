// Typed decoding of rbsim's own messages (for tools that draw or export a recording).
#include <cmath>

#include "cdr_reader.hpp"
#include "rbsim/cdr.hpp"
#include "rbsim/msgs.hpp"

namespace rbsim::msgs {

using detail::Reader;

namespace {

Error bad(const char* type) {
  return Error{std::string("malformed or truncated ") + type + " message"};
}

}  // namespace

Result<SceneMessage> decode_scene(std::span<const std::byte> cdr) {
  Reader r(cdr);
  SceneMessage m;
  m.stamp = r.time();
  (void)r.string();  // frame_id
  m.name = r.string();
  m.description = r.string();
  m.integrator = r.string();
  m.dt = r.get<double>();
  m.duration = r.get<double>();
  m.step_count = r.get<std::uint64_t>();
  m.bodies.resize(r.length(44));
  for (auto& b : m.bodies) {
    b.mass = r.get<double>();
    b.inertia = r.get<double>();
    b.radius = r.get<double>();
    b.color = r.color();
    b.hull.resize(r.length(16));
    for (auto& v : b.hull) v = r.vec2();
  }
  const std::uint32_t springs = r.length(64);
  m.springs.resize(springs);
  m.spring_colors.resize(springs);
  for (std::uint32_t k = 0; k < springs; ++k) {
    SpringDef& s = m.springs[k];
    s.body_i = r.get<std::int32_t>();
    s.anchor_i = r.vec2();
    s.body_j = r.get<std::int32_t>();
    s.anchor_j = r.vec2();
    s.stiffness = r.get<double>();
    s.rest_length = r.get<double>();
    m.spring_colors[k] = r.color();
  }
  m.gravity.resize(r.length(16));
  for (auto& g : m.gravity) g.acceleration = r.vec2();
  m.winds.resize(r.length(28));
  for (auto& w : m.winds) {
    w.beta = r.get<double>();
    w.velocity = r.vec2();
    w.points_per_edge = r.get<std::int32_t>();
  }
  const bool has_viewport = r.get<std::uint8_t>() != 0;
  Viewport vp;
  vp.cx = r.get<double>();
  vp.cy = r.get<double>();
  vp.size = r.get<double>();
  if (has_viewport) m.viewport = vp;
  m.background = r.color();
  if (!r.ok()) return bad("SceneDescription");
  for (const SpringDef& s : m.springs) {
    for (std::int32_t end : {s.body_i, s.body_j}) {
      if (end < kFixed || end >= static_cast<std::int32_t>(m.bodies.size())) return bad("SceneDescription");
    }
  }
  return m;
}

Status decode_body_states(std::span<const std::byte> cdr, BodyStatesMessage& out) {
  Reader r(cdr);
  out.stamp = r.time();
  r.skip_string();  // frame_id
  out.step = r.get<std::uint64_t>();
  out.bodies.resize(r.length(52));
  for (auto& b : out.bodies) {
    b.id = r.get<std::int32_t>();
    b.state.position = r.vec2();
    b.state.theta = r.get<double>();
    b.state.velocity = r.vec2();
    b.state.omega = r.get<double>();
  }
  if (!r.ok()) return bad("BodyStates");
  return Ok{};
}

Status decode_spring_states(std::span<const std::byte> cdr, SpringStatesMessage& out) {
  Reader r(cdr);
  out.stamp = r.time();
  r.skip_string();  // frame_id
  out.step = r.get<std::uint64_t>();
  out.springs.resize(r.length(60));
  for (auto& s : out.springs) {
    s.id = r.get<std::int32_t>();
    s.end_i = r.vec2();
    s.end_j = r.vec2();
    s.length = r.get<double>();
    s.rest_length = r.get<double>();
    s.potential = r.get<double>();
  }
  if (!r.ok()) return bad("SpringStates");
  return Ok{};
}

Status decode_energy_terms(std::span<const std::byte> cdr, EnergyTermsMessage& out,
                           EnergyTermsVersion version) {
  Reader r(cdr);
  out.stamp = r.time();
  r.skip_string();  // frame_id
  out.step = r.get<std::uint64_t>();
  out.bodies.resize(r.length(52));
  for (auto& b : out.bodies) {
    b.id = r.get<std::int32_t>();
    b.momentum = r.vec2();
    b.l_point = r.get<double>();
    b.l_spin = r.get<double>();
    b.t_point = r.get<double>();
    b.t_spin = r.get<double>();
  }
  out.forces.resize(r.length(13));
  for (auto& f : out.forces) {
    f.kind = r.get<std::uint8_t>();
    f.index = r.get<std::int32_t>();
    f.potential = r.get<double>();
  }
  out.momentum = r.vec2();
  out.angular_momentum = r.get<double>();
  out.potential = r.get<double>();
  out.kinetic_point = r.get<double>();
  out.kinetic_spin = r.get<double>();
  out.total = r.get<double>();
  out.has_split = version == EnergyTermsVersion::Current;
  out.potential_gravity = out.has_split ? r.get<double>() : 0.0;
  out.potential_spring = out.has_split ? r.get<double>() : 0.0;
  if (!r.ok()) return bad("EnergyTerms");
  return Ok{};
}

Status decode_poses(std::span<const std::byte> cdr, PosesMessage& out) {
  Reader r(cdr);
  out.stamp = r.time();
  r.skip_string();  // frame_id
  out.poses.resize(r.length(56));
  for (auto& p : out.poses) {
    p.x = r.get<double>();
    p.y = r.get<double>();
    p.z = r.get<double>();
    p.qx = r.get<double>();
    p.qy = r.get<double>();
    p.qz = r.get<double>();
    p.qw = r.get<double>();
  }
  if (!r.ok()) return bad("PoseArray");
  return Ok{};
}

namespace {
// One visualization_msgs/Marker as rbsim writes it: the trailing texture, text and mesh fields
// are read past (they must be well-formed) but not kept.
void read_marker(Reader& r, MarkerMessage& m) {
  m.stamp = r.time();
  m.frame_id = r.string();
  m.ns = r.string();
  m.id = r.get<std::int32_t>();
  m.type = r.get<std::int32_t>();
  m.action = r.get<std::int32_t>();
  m.pose.x = r.get<double>();
  m.pose.y = r.get<double>();
  m.pose.z = r.get<double>();
  m.pose.qx = r.get<double>();
  m.pose.qy = r.get<double>();
  m.pose.qz = r.get<double>();
  m.pose.qw = r.get<double>();
  m.scale_x = r.get<double>();
  m.scale_y = r.get<double>();
  m.scale_z = r.get<double>();
  for (float& c : m.color) c = r.get<float>();
  m.lifetime = r.time();
  m.frame_locked = r.get<std::uint8_t>() != 0;
  m.points.resize(r.length(24));
  for (Vec2& p : m.points) {
    p = r.vec2();
    (void)r.get<double>();  // z
  }
  m.colors.resize(r.length(16));
  for (auto& c : m.colors) {
    for (float& x : c) x = r.get<float>();
  }
  r.skip_string();  // texture_resource
  (void)r.time();   // texture.header
  r.skip_string();
  r.skip_string();                                                              // texture.format
  for (std::uint32_t n = r.length(1); n > 0; --n) (void)r.get<std::uint8_t>();  // texture.data
  for (std::uint32_t n = r.length(8); n > 0; --n) {                             // uv_coordinates
    (void)r.get<float>();
    (void)r.get<float>();
  }
  r.skip_string();                                                              // text
  r.skip_string();                                                              // mesh_resource
  r.skip_string();                                                              // mesh_file.filename
  for (std::uint32_t n = r.length(1); n > 0; --n) (void)r.get<std::uint8_t>();  // mesh_file.data
  (void)r.get<std::uint8_t>();                                                  // mesh_use_embedded_materials
}
}  // namespace

Status decode_tf(std::span<const std::byte> cdr, TfMessage& out) {
  Reader r(cdr);
  out.transforms.resize(r.length(80));
  for (auto& t : out.transforms) {
    t.stamp = r.time();
    t.frame_id = r.string();
    t.child_frame_id = r.string();
    t.x = r.get<double>();
    t.y = r.get<double>();
    t.z = r.get<double>();
    t.qx = r.get<double>();
    t.qy = r.get<double>();
    t.qz = r.get<double>();
    t.qw = r.get<double>();
  }
  if (!r.ok()) return bad("TFMessage");
  return Ok{};
}

Status decode_marker(std::span<const std::byte> cdr, MarkerMessage& out) {
  Reader r(cdr);
  read_marker(r, out);
  if (!r.ok()) return bad("Marker");
  return Ok{};
}

Status decode_marker_array(std::span<const std::byte> cdr, std::vector<MarkerMessage>& out) {
  Reader r(cdr);
  out.resize(r.length(100));
  for (MarkerMessage& m : out) read_marker(r, m);
  if (!r.ok()) return bad("MarkerArray");
  return Ok{};
}

std::optional<Time> decode_stamp(TopicId id, std::span<const std::byte> cdr) {
  if (id == TopicId::SceneDescription) return std::nullopt;
  Reader r(cdr);
  if ((id == TopicId::Markers || id == TopicId::Tf) && r.get<std::uint32_t>() == 0) return std::nullopt;
  if (id == TopicId::Commands) {  // seq, step, then the stamp
    r.get<std::uint64_t>();
    r.get<std::uint64_t>();
  }
  const Time t = r.time();
  if (!r.ok()) return std::nullopt;
  return t;
}

std::optional<std::uint64_t> message_step(TopicId id, std::span<const std::byte> cdr, double dt) {
  if (id == TopicId::BodyStates || id == TopicId::SpringStates || id == TopicId::Energy) {
    Reader r(cdr);
    r.time();
    r.skip_string();  // header.frame_id
    const auto step = r.get<std::uint64_t>();
    if (!r.ok()) return std::nullopt;
    return step;
  }
  if (id == TopicId::Commands) {  // seq, then the step it applied at
    Reader r(cdr);
    r.get<std::uint64_t>();
    const auto step = r.get<std::uint64_t>();
    if (!r.ok()) return std::nullopt;
    return step;
  }
  std::optional<Time> stamp = decode_stamp(id, cdr);
  if (id == TopicId::SceneDescription) {  // the step it describes the world at (an epoch's first)
    Reader r(cdr);
    stamp = r.time();
    if (!r.ok()) return std::nullopt;
  }
  if (!stamp || !std::isfinite(dt) || !(dt > 0.0)) return std::nullopt;
  // Stamps are written as sec + nanosec of step * dt; rounding undoes the nanosecond truncation.
  const double ns = static_cast<double>(stamp->sec) * 1e9 + static_cast<double>(stamp->nanosec);
  const double k = std::round(ns / (dt * 1e9));
  if (!(k > 0.0)) return 0;
  return k >= 1.8e19 ? UINT64_MAX : static_cast<std::uint64_t>(k);
}

bool is_command_metadata(std::string_view field_path) {
  // Command.msg's words about a command, not the command: where it came from and its reply text.
  return field_path == "source" || field_path == "message";
}

bool is_scene_metadata(std::string_view field_path) {
  // SceneDescription.msg's fields that do not change the simulation.
  return field_path == "name" || field_path == "description" || field_path == "has_viewport" ||
         field_path.starts_with("viewport_") || field_path.starts_with("background.");
}

}  // namespace rbsim::msgs
