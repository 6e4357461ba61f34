// Our CDR encoder (rbsim::msgs::Encoder) against Eclipse Cyclone DDS 0.10.
//
// For every topic type, the same world snapshot is encoded twice, independently:
//   - by rbsim::msgs::Encoder, and
//   - by filling the idlc-generated C struct (types generated at build time from the same .msg
//     files, via msg2idl.py and idlc) field by field from the .msg semantics, then letting Cyclone
//     serialise it on a real DDS write (writer and reader in one participant, loopback config,
//     raw bytes taken with dds_takecdr).
// The two byte strings must be identical, encapsulation header included. The byte identity across
// every topic type is the real structural agreement check between the .msg definitions, our
// encoder and the generated IDL: a missing, extra, reordered or retyped field anywhere shifts or
// changes bytes. GeneratedIdl.* adds a field-by-field op-code check for every generated type,
// which names the offending field when they disagree.
//
// The reverse direction is checked too: Cyclone deserialises our bytes to the same sample, and a
// serdata built from our raw bytes can be published with dds_writecdr (the node's publishing
// path) and arrives unchanged.
#include <gtest/gtest.h>

#include <dds/dds.h>
#include <dds/ddsi/ddsi_serdata.h>
#include <dds/ddsi/ddsi_sertype.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <span>
#include <sstream>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "generated_types.inc"  // every idlc-generated header, and kGeneratedTypes
#include "raw_serdata.hpp"
#include "rbsim/builders.hpp"
#include "rbsim/interfaces.hpp"
#include "rbsim/msgs.hpp"
#include "rbsim/simulation_interfaces.hpp"
#include "rbsim/type_hash.hpp"

namespace {

using rbsim::Scene;
using rbsim::World;
using rbsim::msgs::Bytes;
using rbsim::msgs::TopicId;

// ---------------------------------------------------------------------------------------------
// The snapshot: several bodies, springs (one with a fixed end), two gravity fields, two winds, a
// viewport, custom colours, a multi-byte UTF-8 description, and a time past one second so both
// stamp fields are non-zero.

Scene test_scene() {
  Scene scene;
  scene.name = "cdr-check";
  scene.description = "four bodies, springs, gravity and wind \xE2\x80\x94 byte check";
  scene.world = rbsim::builders::grid(4, /*wind_and_springs=*/true);
  scene.world.dt = 0.125;
  scene.world.gravity.push_back(rbsim::GravityDef{{0.25, 0.0}});
  scene.world.winds.push_back(rbsim::WindDef{0.125, {-1.0, 0.75}, 2});
  scene.duration = 3.0;
  scene.viewport = rbsim::Viewport{1.5, -2.0, 4.0};
  scene.background = rbsim::Color{0.9, 0.95, 1.0};
  for (int b = 0; b < 4; ++b) scene.body_colors.push_back(rbsim::default_body_color(b));
  for (std::size_t k = 0; k < scene.world.springs.size(); ++k) {
    scene.spring_colors.push_back(rbsim::Color{0.1 * static_cast<double>(k), 0.2, 0.3});
  }
  return scene;
}

constexpr int kSteps = 9;  // t = 9 * 0.125 s = 1.125 s

// ---------------------------------------------------------------------------------------------
// Filling the generated C structs, written from the .msg files (and, for the content of the
// visualisation messages, from the documentation in encode.cpp). Memory comes from dds_alloc /
// dds_string_dup so dds_sample_free releases it.

char* str(std::string_view s) {
  return dds_string_dup(std::string(s).c_str());
}

template <class Seq>
auto* alloc_seq(Seq& seq, std::size_t n) {
  using Elem = std::remove_pointer_t<decltype(seq._buffer)>;
  seq._maximum = static_cast<std::uint32_t>(n);
  seq._length = static_cast<std::uint32_t>(n);
  seq._release = true;
  seq._buffer = nullptr;
  if (n > 0) {
    seq._buffer = static_cast<Elem*>(dds_alloc(n * sizeof(Elem)));
    std::memset(static_cast<void*>(seq._buffer), 0, n * sizeof(Elem));
  }
  return seq._buffer;
}

// builtin_interfaces/Time of the current step: t = step * dt, to the nearest nanosecond.
builtin_interfaces_msg_dds__Time_ stamp_of(const World& w) {
  const double t = static_cast<double>(w.step_index()) * w.dt();
  const auto ns = static_cast<std::int64_t>(std::llround(t * 1e9));
  return {static_cast<std::int32_t>(ns / 1'000'000'000), static_cast<std::uint32_t>(ns % 1'000'000'000)};
}

void set_header(std_msgs_msg_dds__Header_& h, builtin_interfaces_msg_dds__Time_ stamp,
                std::string_view frame) {
  h.stamp = stamp;
  h.frame_id = str(frame);
}

rbsim_msgs_msg_dds__Vector2_ vec2(const rbsim::Vec2& v) {
  return {v.x(), v.y()};
}

std_msgs_msg_dds__ColorRGBA_ rgba(const rbsim::Color& c) {
  return {static_cast<float>(c.r), static_cast<float>(c.g), static_cast<float>(c.b), 1.0f};
}

geometry_msgs_msg_dds__Point_ point3(const rbsim::Vec2& p) {
  return {p.x(), p.y(), 0.0};
}

// A planar pose: (x, y, 0), rotated by theta about +z.
geometry_msgs_msg_dds__Pose_ planar_pose(double x, double y, double theta) {
  geometry_msgs_msg_dds__Pose_ p{};
  p.position = {x, y, 0.0};
  p.orientation = {0.0, 0.0, std::sin(theta / 2.0), std::cos(theta / 2.0)};
  return p;
}

void fill_scene(const Scene& s, const World& w, void* out) {
  auto& m = *static_cast<rbsim_msgs_msg_dds__SceneDescription_*>(out);
  set_header(m.header, stamp_of(w), "world");
  m.name = str(s.name);
  m.description = str(s.description);
  m.integrator =
      str(w.integrator() == rbsim::Integrator::ExplicitEuler ? "explicit-euler" : "symplectic-euler");
  m.dt = w.dt();
  m.duration = s.duration;
  m.step_count = static_cast<std::uint64_t>(std::ceil(s.duration / w.dt()));
  auto* bodies = alloc_seq(m.bodies, static_cast<std::size_t>(w.body_count()));
  for (std::int32_t b = 0; b < w.body_count(); ++b) {
    const rbsim::BodyId id{b};
    auto& d = bodies[b];
    d.mass = w.mass(id);
    d.inertia = w.inertia(id);
    d.radius = w.radius(id);
    d.color = rgba(s.body_colors[static_cast<std::size_t>(b)]);
    const auto hull = w.hull(id);
    auto* h = alloc_seq(d.hull, hull.size());
    for (std::size_t i = 0; i < hull.size(); ++i) h[i] = vec2(hull[i]);
  }
  auto* springs = alloc_seq(m.springs, static_cast<std::size_t>(w.spring_count()));
  for (std::int32_t k = 0; k < w.spring_count(); ++k) {
    const rbsim::SpringDef& def = w.spring(rbsim::SpringId{k});
    auto& d = springs[k];
    d.body_i = def.body_i;
    d.anchor_i = vec2(def.anchor_i);
    d.body_j = def.body_j;
    d.anchor_j = vec2(def.anchor_j);
    d.stiffness = def.stiffness;
    d.rest_length = def.rest_length;
    d.color = rgba(s.spring_colors[static_cast<std::size_t>(k)]);
  }
  auto* gravity = alloc_seq(m.gravity, w.gravity().size());
  for (std::size_t g = 0; g < w.gravity().size(); ++g)
    gravity[g].acceleration = vec2(w.gravity()[g].acceleration);
  auto* winds = alloc_seq(m.winds, w.winds().size());
  for (std::size_t i = 0; i < w.winds().size(); ++i) {
    winds[i].beta = w.winds()[i].beta;
    winds[i].velocity = vec2(w.winds()[i].velocity);
    winds[i].points_per_edge = w.winds()[i].points_per_edge;
  }
  m.has_viewport = s.viewport.has_value();
  m.viewport_cx = s.viewport ? s.viewport->cx : 0.0;
  m.viewport_cy = s.viewport ? s.viewport->cy : 0.0;
  m.viewport_size = s.viewport ? s.viewport->size : 1.0;
  m.background = rgba(s.background);
}

void fill_body_states(const Scene&, const World& w, void* out) {
  auto& m = *static_cast<rbsim_msgs_msg_dds__BodyStates_*>(out);
  set_header(m.header, stamp_of(w), "world");
  m.step = static_cast<std::uint64_t>(w.step_index());
  auto* bodies = alloc_seq(m.bodies, static_cast<std::size_t>(w.body_count()));
  for (std::int32_t b = 0; b < w.body_count(); ++b) {
    const rbsim::BodyState st = w.state(rbsim::BodyId{b});
    bodies[b] = {b, st.position.x(), st.position.y(), st.theta, st.velocity.x(), st.velocity.y(), st.omega};
  }
}

void fill_spring_states(const Scene&, const World& w, void* out) {
  auto& m = *static_cast<rbsim_msgs_msg_dds__SpringStates_*>(out);
  set_header(m.header, stamp_of(w), "world");
  m.step = static_cast<std::uint64_t>(w.step_index());
  auto* springs = alloc_seq(m.springs, static_cast<std::size_t>(w.spring_count()));
  for (std::int32_t k = 0; k < w.spring_count(); ++k) {
    const rbsim::SpringState st = w.spring_state(rbsim::SpringId{k});
    springs[k] = {
        k, vec2(st.end_i), vec2(st.end_j), st.length, w.spring(rbsim::SpringId{k}).rest_length, st.potential};
  }
}

// Totals are sums in list order (bodies, then gravity fields, then springs), as the .msg
// comments define them; the same order gives the same rounding.
void fill_energy(const Scene&, const World& w, void* out) {
  auto& m = *static_cast<rbsim_msgs_msg_dds__EnergyTerms_*>(out);
  set_header(m.header, stamp_of(w), "world");
  m.step = static_cast<std::uint64_t>(w.step_index());
  auto* bodies = alloc_seq(m.bodies, static_cast<std::size_t>(w.body_count()));
  double px = 0.0, py = 0.0, angular = 0.0, t_point = 0.0, t_spin = 0.0;
  for (std::int32_t b = 0; b < w.body_count(); ++b) {
    const rbsim::BodyQuantities q = w.quantities(rbsim::BodyId{b});
    bodies[b] = {b, vec2(q.momentum), q.l_point, q.l_spin, q.t_point, q.t_spin};
    px += q.momentum.x();
    py += q.momentum.y();
    angular += q.l_point + q.l_spin;
    t_point += q.t_point;
    t_spin += q.t_spin;
  }
  const std::size_t n_gravity = w.gravity().size();
  auto* forces = alloc_seq(m.forces, n_gravity + static_cast<std::size_t>(w.spring_count()));
  double potential = 0.0;
  for (std::size_t g = 0; g < n_gravity; ++g) {
    // U = -sum_b M_b g . X_b
    const rbsim::Vec2 acc = w.gravity()[g].acceleration;
    double u = 0.0;
    for (std::int32_t b = 0; b < w.body_count(); ++b) {
      u -= w.mass(rbsim::BodyId{b}) * (acc.x() * w.x()[b] + acc.y() * w.y()[b]);
    }
    forces[g] = {rbsim_msgs_msg_dds__ForcePotential_Constants_GRAVITY, static_cast<std::int32_t>(g), u};
    potential += u;
  }
  for (std::int32_t k = 0; k < w.spring_count(); ++k) {
    const double u = w.spring_state(rbsim::SpringId{k}).potential;
    forces[n_gravity + static_cast<std::size_t>(k)] = {rbsim_msgs_msg_dds__ForcePotential_Constants_SPRING, k,
                                                       u};
    potential += u;
  }
  m.momentum = {px, py};
  m.angular_momentum = angular;
  m.potential = potential;
  m.kinetic_point = t_point;
  m.kinetic_spin = t_spin;
  m.total = potential + t_point + t_spin;
  const rbsim::Energy e = w.energy();
  m.potential_gravity = e.u_gravity;
  m.potential_spring = e.u_spring;
}

void fill_poses(const Scene&, const World& w, void* out) {
  auto& m = *static_cast<geometry_msgs_msg_dds__PoseArray_*>(out);
  set_header(m.header, stamp_of(w), "world");
  auto* poses = alloc_seq(m.poses, static_cast<std::size_t>(w.body_count()));
  for (std::int32_t b = 0; b < w.body_count(); ++b) poses[b] = planar_pose(w.x()[b], w.y()[b], w.theta()[b]);
}

// Everything not described by the marker is empty: no texture, mesh, text or per-vertex UVs.
void marker_defaults(visualization_msgs_msg_dds__Marker_& mk, builtin_interfaces_msg_dds__Time_ stamp,
                     std::string_view ns, std::int32_t id, std::int32_t type,
                     std::string_view frame = "world") {
  set_header(mk.header, stamp, frame);
  mk.ns = str(ns);
  mk.id = id;
  mk.type = type;
  mk.action = visualization_msgs_msg_dds__Marker_Constants_ADD;
  mk.lifetime = {0, 0};  // forever
  mk.frame_locked = false;
  mk.texture_resource = str("");
  set_header(mk.texture.header, {0, 0}, "");
  mk.texture.format = str("");
  alloc_seq(mk.texture.data, 0);
  alloc_seq(mk.uv_coordinates, 0);
  mk.text = str("");
  mk.mesh_resource = str("");
  mk.mesh_file.filename = str("");
  alloc_seq(mk.mesh_file.data, 0);
  mk.mesh_use_embedded_materials = false;
}

// Per body, in its frame "rbsim/body_<i>" (frame-locked): its hull as a TRIANGLE_LIST (scale 1) and
// its closed outline as a LINE_STRIP of width 2 r, both in the body's colour. Then the fixed spring
// anchors as one SPHERE_LIST in world (0.15 across), each in its spring's colour.
void fill_markers(const Scene& s, const World& w, void* out) {
  auto& m = *static_cast<visualization_msgs_msg_dds__MarkerArray_*>(out);
  const auto stamp = stamp_of(w);
  std::vector<rbsim::Vec2> anchors;
  std::vector<rbsim::Color> anchor_colors;
  for (std::int32_t k = 0; k < w.spring_count(); ++k) {
    const rbsim::SpringDef& sp = w.spring(rbsim::SpringId{k});
    if (sp.body_i == rbsim::kFixed)
      anchors.push_back(sp.anchor_i), anchor_colors.push_back(s.spring_colors[k]);
    if (sp.body_j == rbsim::kFixed)
      anchors.push_back(sp.anchor_j), anchor_colors.push_back(s.spring_colors[k]);
  }
  const auto n = static_cast<std::size_t>(w.body_count());
  auto* markers = alloc_seq(m.markers, 2 * n + (anchors.empty() ? 0 : 1));
  for (std::int32_t b = 0; b < w.body_count(); ++b) {
    const rbsim::BodyId id{b};
    const std::string frame = "rbsim/body_" + std::to_string(b);
    const auto hull = w.hull(id);
    auto& fill = markers[2 * b];
    marker_defaults(fill, stamp, "hulls", b, visualization_msgs_msg_dds__Marker_Constants_TRIANGLE_LIST,
                    frame);
    fill.pose = planar_pose(0.0, 0.0, 0.0);
    fill.scale = {1.0, 1.0, 1.0};
    fill.color = rgba(s.body_colors[static_cast<std::size_t>(b)]);
    fill.frame_locked = true;
    const std::vector<std::uint32_t> tri = rbsim::msgs::triangulate(hull);
    auto* tp = alloc_seq(fill.points, tri.size());
    for (std::size_t i = 0; i < tri.size(); ++i) tp[i] = point3(hull[tri[i]]);
    alloc_seq(fill.colors, 0);
    auto& line = markers[2 * b + 1];
    marker_defaults(line, stamp, "outlines", b, visualization_msgs_msg_dds__Marker_Constants_LINE_STRIP,
                    frame);
    line.pose = planar_pose(0.0, 0.0, 0.0);
    line.scale = {2.0 * w.radius(id), 0.0, 0.0};
    line.color = rgba(s.body_colors[static_cast<std::size_t>(b)]);
    line.frame_locked = true;
    auto* pts = alloc_seq(line.points, hull.size() + 1);
    for (std::size_t i = 0; i < hull.size(); ++i) pts[i] = point3(hull[i]);
    pts[hull.size()] = point3(hull[0]);
    alloc_seq(line.colors, 0);
  }
  if (!anchors.empty()) {
    auto& mk = markers[2 * n];
    marker_defaults(mk, stamp, "anchors", 0, visualization_msgs_msg_dds__Marker_Constants_SPHERE_LIST);
    mk.pose = planar_pose(0.0, 0.0, 0.0);
    mk.scale = {0.15, 0.15, 0.15};
    mk.color = rgba(rbsim::Color{0.25, 0.25, 0.25});
    auto* pts = alloc_seq(mk.points, anchors.size());
    auto* colors = alloc_seq(mk.colors, anchors.size());
    for (std::size_t k = 0; k < anchors.size(); ++k) {
      pts[k] = point3(anchors[k]);
      colors[k] = rgba(anchor_colors[k]);
    }
  }
}

// One LINE_LIST in world of every spring (width 0.05, grey), each segment in its spring's colour.
void fill_springs(const Scene& s, const World& w, void* out) {
  auto& mk = *static_cast<visualization_msgs_msg_dds__Marker_*>(out);
  marker_defaults(mk, stamp_of(w), "springs", 0, visualization_msgs_msg_dds__Marker_Constants_LINE_LIST);
  mk.pose = planar_pose(0.0, 0.0, 0.0);
  mk.scale = {0.05, 0.0, 0.0};
  mk.color = rgba(rbsim::Color{0.25, 0.25, 0.25});
  const auto n = static_cast<std::size_t>(w.spring_count());
  auto* pts = alloc_seq(mk.points, 2 * n);
  auto* colors = alloc_seq(mk.colors, 2 * n);
  for (std::size_t k = 0; k < n; ++k) {
    const rbsim::SpringState st = w.spring_state(rbsim::SpringId{static_cast<std::int32_t>(k)});
    pts[2 * k] = point3(st.end_i);
    pts[2 * k + 1] = point3(st.end_j);
    colors[2 * k] = colors[2 * k + 1] = rgba(s.spring_colors[k]);
  }
}

// One TransformStamped per body: world -> rbsim/body_<i>, translation (x, y, 0), rotation theta about z.
void fill_tf(const Scene&, const World& w, void* out) {
  auto& m = *static_cast<tf2_msgs_msg_dds__TFMessage_*>(out);
  auto* ts = alloc_seq(m.transforms, static_cast<std::size_t>(w.body_count()));
  for (std::int32_t b = 0; b < w.body_count(); ++b) {
    set_header(ts[b].header, stamp_of(w), "world");
    ts[b].child_frame_id = str("rbsim/body_" + std::to_string(b));
    ts[b].transform.translation = {w.x()[b], w.y()[b], 0.0};
    ts[b].transform.rotation = {0.0, 0.0, std::sin(0.5 * w.theta()[b]), std::cos(0.5 * w.theta()[b])};
  }
}

void fill_clock(const Scene&, const World& w, void* out) {
  static_cast<rosgraph_msgs_msg_dds__Clock_*>(out)->clock = stamp_of(w);
}

struct TypeCase {
  TopicId id;
  const dds_topic_descriptor_t* desc;
  void (*fill)(const Scene&, const World&, void*);
};

const TypeCase kCases[] = {
    {TopicId::SceneDescription, &rbsim_msgs_msg_dds__SceneDescription__desc, fill_scene},
    {TopicId::BodyStates, &rbsim_msgs_msg_dds__BodyStates__desc, fill_body_states},
    {TopicId::SpringStates, &rbsim_msgs_msg_dds__SpringStates__desc, fill_spring_states},
    {TopicId::Energy, &rbsim_msgs_msg_dds__EnergyTerms__desc, fill_energy},
    {TopicId::Poses, &geometry_msgs_msg_dds__PoseArray__desc, fill_poses},
    {TopicId::Markers, &visualization_msgs_msg_dds__MarkerArray__desc, fill_markers},
    {TopicId::Tf, &tf2_msgs_msg_dds__TFMessage__desc, fill_tf},
    {TopicId::Springs, &visualization_msgs_msg_dds__Marker__desc, fill_springs},
    {TopicId::Clock, &rosgraph_msgs_msg_dds__Clock__desc, fill_clock},
};

const TypeCase* find_case(TopicId id) {
  for (const TypeCase& c : kCases) {
    if (c.id == id) return &c;
  }
  return nullptr;
}

// ---------------------------------------------------------------------------------------------
// Owning wrappers around Cyclone objects.

// A C sample of a generated type, zero-initialised; dds_sample_free releases it and its contents.
class Sample {
 public:
  explicit Sample(const dds_topic_descriptor_t& desc) : desc_(&desc), p_(dds_alloc(desc.m_size)) {
    std::memset(p_, 0, desc.m_size);
  }
  ~Sample() { dds_sample_free(p_, desc_, DDS_FREE_ALL); }
  Sample(const Sample&) = delete;
  Sample& operator=(const Sample&) = delete;
  void* get() const { return p_; }

 private:
  const dds_topic_descriptor_t* desc_;
  void* p_;
};

struct SerdataUnref {
  void operator()(ddsi_serdata* d) const { ddsi_serdata_unref(d); }
};
using SerdataPtr = std::unique_ptr<ddsi_serdata, SerdataUnref>;

// The serialised form of a serdata: ddsi_serdata_size includes the 4-byte encapsulation header
// and ddsi_serdata_to_ser copies it along with the payload.
Bytes serialized(const ddsi_serdata& d) {
  const std::uint32_t n = ddsi_serdata_size(&d);
  Bytes out(n);
  ddsi_serdata_to_ser(&d, 0, n, out.data());
  return out;
}

// A serdata of `type` holding the given CDR bytes (header included), as if received.
SerdataPtr serdata_from_cdr(const ddsi_sertype* type, const Bytes& cdr) {
  ddsrt_iovec_t iov;
  iov.iov_base = const_cast<std::byte*>(cdr.data());
  iov.iov_len = cdr.size();
  return SerdataPtr(ddsi_serdata_from_ser_iov(type, SDK_DATA, 1, &iov, cdr.size()));
}

std::string hex(std::span<const std::byte> b, std::size_t from, std::size_t to) {
  std::ostringstream os;
  char buf[4];
  for (std::size_t i = from; i < to && i < b.size(); ++i) {
    std::snprintf(buf, sizeof buf, "%02x ", static_cast<unsigned>(b[i]));
    os << buf;
  }
  return os.str();
}

::testing::AssertionResult same_bytes(std::span<const std::byte> ours, std::span<const std::byte> cyclone) {
  if (ours.size() == cyclone.size() && std::equal(ours.begin(), ours.end(), cyclone.begin())) {
    return ::testing::AssertionSuccess() << ours.size() << " identical bytes";
  }
  const auto at = static_cast<std::size_t>(
      std::mismatch(ours.begin(), ours.end(), cyclone.begin(), cyclone.end()).first - ours.begin());
  const std::size_t from = at < 8 ? 0 : at - 8;
  return ::testing::AssertionFailure()
         << "ours " << ours.size() << " bytes, Cyclone " << cyclone.size()
         << " bytes; first difference at byte " << at << "\n  ours:    ..." << hex(ours, from, at + 8)
         << "\n  Cyclone: ..." << hex(cyclone, from, at + 8);
}

// Raw CDR is handed to dds_writecdr through the node's raw-bytes serdata (node/dds/src/raw_serdata.cpp).

// ---------------------------------------------------------------------------------------------
// DDS plumbing: one participant per test on a private domain, a topic of the type under test,
// and a reliable writer/reader pair in that participant. Every wait is bounded.

constexpr dds_duration_t kTimeout = DDS_SECS(5);

dds_domainid_t test_domain() {
  const char* env = std::getenv("RBSIM_DDS_TEST_DOMAIN");
  return env != nullptr ? static_cast<dds_domainid_t>(std::strtoul(env, nullptr, 10)) : 142;
}

class Loopback {
 public:
  Loopback() = default;
  ~Loopback() {
    if (participant_ > 0) dds_delete(participant_);  // deletes every child entity too
  }
  Loopback(const Loopback&) = delete;
  Loopback& operator=(const Loopback&) = delete;

  // Creates the entities; the topic name is unique per process and type, since several test
  // processes may share the domain.
  // With `raw_writer`, the writer's topic has rbsim's raw CDR sertype (as rbsim's publishers do)
  // under the same topic and type name; the reader's always has the idlc type.
  void open(const dds_topic_descriptor_t& desc, bool raw_writer = false) {
    participant_ = dds_create_participant(test_domain(), nullptr, nullptr);
    ASSERT_GT(participant_, 0) << "dds_create_participant: " << dds_strretcode(participant_);
    const std::string name = "rbsim_cdr_test_" + std::to_string(::getpid()) + "_" + desc.m_typename;
    std::string topic_name = name;
    std::replace(topic_name.begin(), topic_name.end(), ':', '_');
    topic_ = dds_create_topic(participant_, &desc, topic_name.c_str(), nullptr, nullptr);
    ASSERT_GT(topic_, 0) << "dds_create_topic: " << dds_strretcode(topic_);
    dds_entity_t writer_topic = topic_;
    if (raw_writer) {
      ddsi_sertype* raw = rbsim::node::make_raw_sertype(desc.m_typename);
      writer_topic =
          dds_create_topic_sertype(participant_, topic_name.c_str(), &raw, nullptr, nullptr, nullptr);
      ASSERT_GT(writer_topic, 0) << "dds_create_topic_sertype: " << dds_strretcode(writer_topic);
      raw_type_ = raw;
    }
    dds_qos_t* qos = dds_create_qos();
    dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
    dds_qset_history(qos, DDS_HISTORY_KEEP_ALL, 0);
    writer_ = dds_create_writer(participant_, writer_topic, qos, nullptr);
    reader_ = dds_create_reader(participant_, topic_, qos, nullptr);
    dds_delete_qos(qos);
    ASSERT_GT(writer_, 0) << "dds_create_writer: " << dds_strretcode(writer_);
    ASSERT_GT(reader_, 0) << "dds_create_reader: " << dds_strretcode(reader_);
    waitset_ = dds_create_waitset(participant_);
    ASSERT_GT(waitset_, 0);
    const dds_entity_t cond = dds_create_readcondition(reader_, DDS_ANY_STATE);
    ASSERT_GT(cond, 0);
    ASSERT_EQ(dds_waitset_attach(waitset_, cond, reader_), DDS_RETCODE_OK);
    // Local matching is immediate in Cyclone, but do not rely on it.
    const dds_time_t deadline = dds_time() + kTimeout;
    dds_publication_matched_status_t st{};
    while (dds_get_publication_matched_status(writer_, &st) == DDS_RETCODE_OK && st.current_count < 1 &&
           dds_time() < deadline) {
      dds_sleepfor(DDS_MSECS(5));
    }
    ASSERT_GE(st.current_count, 1u) << "writer and reader did not match within 5 s";
  }

  dds_entity_t writer() const { return writer_; }
  const ddsi_sertype* raw_type() const { return raw_type_; }

  // The next valid sample as Cyclone stores it, or null after kTimeout.
  SerdataPtr take() {
    const dds_time_t deadline = dds_time() + kTimeout;
    for (;;) {
      ddsi_serdata* d = nullptr;
      dds_sample_info_t info;
      const dds_return_t n = dds_takecdr(reader_, &d, 1, &info, DDS_ANY_STATE);
      if (n < 0) {
        ADD_FAILURE() << "dds_takecdr: " << dds_strretcode(n);
        return nullptr;
      }
      if (n == 1) {
        SerdataPtr owned(d);
        if (info.valid_data) return owned;
        continue;
      }
      const dds_time_t now = dds_time();
      if (now >= deadline) {
        ADD_FAILURE() << "no sample within 5 s";
        return nullptr;
      }
      (void)dds_waitset_wait(waitset_, nullptr, 0, deadline - now);
    }
  }

  // Publishes a C sample and returns Cyclone's serialisation of it (as received).
  SerdataPtr write_sample(const void* sample) {
    const dds_return_t rc = dds_write(writer_, sample);
    EXPECT_EQ(rc, DDS_RETCODE_OK) << "dds_write: " << dds_strretcode(rc);
    return rc == DDS_RETCODE_OK ? take() : nullptr;
  }

  // Publishes a serdata (ownership passes to Cyclone) and returns what the reader gets.
  SerdataPtr write_cdr(SerdataPtr d) {
    const dds_return_t rc = dds_writecdr(writer_, d.release());
    EXPECT_EQ(rc, DDS_RETCODE_OK) << "dds_writecdr: " << dds_strretcode(rc);
    return rc == DDS_RETCODE_OK ? take() : nullptr;
  }

 private:
  dds_entity_t participant_ = 0, topic_ = 0, writer_ = 0, reader_ = 0, waitset_ = 0;
  const ddsi_sertype* raw_type_ = nullptr;
};

// ---------------------------------------------------------------------------------------------
// The per-topic fixture: the world after kSteps steps, our bytes and the independent C sample.

class CycloneCdr : public ::testing::TestWithParam<TopicId> {
 protected:
  void SetUp() override {
    tc_ = find_case(GetParam());
    ASSERT_NE(tc_, nullptr);
    scene_ = test_scene();
    auto w = World::create(scene_.world);
    ASSERT_TRUE(w.ok()) << w.error().message;
    world_ = std::make_unique<World>(std::move(w.value()));
    for (int i = 0; i < kSteps; ++i) world_->step();
    ASSERT_FALSE(world_->find_nonfinite().has_value());
    rbsim::msgs::Encoder(scene_).encode(GetParam(), *world_, ours_);
    sample_ = std::make_unique<Sample>(*tc_->desc);
    tc_->fill(scene_, *world_, sample_->get());
    ASSERT_NO_FATAL_FAILURE(dds_.open(*tc_->desc));
  }

  const TypeCase* tc_ = nullptr;
  Scene scene_;
  std::unique_ptr<World> world_;
  Bytes ours_;
  std::unique_ptr<Sample> sample_;
  Loopback dds_;
};

TEST_P(CycloneCdr, EncoderBytesEqualCycloneSerialisation) {
  // Encapsulation header: 00 01 = plain little-endian CDR (XCDR1), then the options, 00 0p,
  // where p counts the zero bytes padding the message to a multiple of 4. Only the markers end
  // unaligned (on a bool), so every other topic starts with exactly 00 01 00 00.
  ASSERT_GE(ours_.size(), 4u);
  EXPECT_EQ(hex(ours_, 0, 3), "00 01 00 ");
  const auto pad = static_cast<std::size_t>(ours_[3]);
  ASSERT_LE(pad, 3u);
  EXPECT_EQ(ours_.size() % 4, 0u);
  for (std::size_t i = ours_.size() - pad; i < ours_.size(); ++i)
    EXPECT_EQ(ours_[i], std::byte{0}) << "pad byte " << i;
  if (GetParam() == TopicId::Markers || GetParam() == TopicId::Springs) {
    EXPECT_EQ(pad, 3u);  // a Marker ends with a bool
  } else {
    EXPECT_EQ(hex(ours_, 0, 4), "00 01 00 00 ");
  }
  const SerdataPtr cyclone = dds_.write_sample(sample_->get());
  ASSERT_NE(cyclone, nullptr);
  // Cyclone's serialised form (ddsi_serdata_size / ddsi_serdata_to_ser) includes the 4-byte
  // encapsulation header, so the whole messages compare.
  const Bytes theirs = serialized(*cyclone);
  ASSERT_GE(theirs.size(), 4u);
  EXPECT_EQ(hex(theirs, 0, 2), "00 01 ");
  EXPECT_TRUE(same_bytes(ours_, theirs));
}

TEST_P(CycloneCdr, CycloneDeserialisesEncoderBytesToTheSameSample) {
  const SerdataPtr reference = dds_.write_sample(sample_->get());
  ASSERT_NE(reference, nullptr);
  const ddsi_sertype* type = reference->type;  // the topic's default sertype
  const SerdataPtr parsed = serdata_from_cdr(type, ours_);
  ASSERT_NE(parsed, nullptr) << "Cyclone rejected our bytes";
  Sample decoded(*tc_->desc);
  ASSERT_TRUE(ddsi_serdata_to_sample(parsed.get(), decoded.get(), nullptr, nullptr));
  // Sample equality through Cyclone's own serialiser (injective for these types: every field is
  // written, no padding is ambiguous): serialise the decoded sample and the independently
  // filled one and compare.
  const SerdataPtr again(ddsi_serdata_from_sample(type, SDK_DATA, decoded.get()));
  ASSERT_NE(again, nullptr);
  EXPECT_TRUE(same_bytes(serialized(*again), serialized(*reference)));
}

TEST_P(CycloneCdr, WritecdrWithTheTopicSertypePublishesEncoderBytesUnchanged) {
  // The default sertype pointer, from a sample taken off the topic (0.10 has no getter).
  const SerdataPtr first = dds_.write_sample(sample_->get());
  ASSERT_NE(first, nullptr);
  SerdataPtr ours = serdata_from_cdr(first->type, ours_);
  ASSERT_NE(ours, nullptr);
  const SerdataPtr got = dds_.write_cdr(std::move(ours));
  ASSERT_NE(got, nullptr);
  EXPECT_TRUE(same_bytes(serialized(*got), ours_));
}

TEST_P(CycloneCdr, RawTypeWriterDeliversEncoderBytesToAReaderOfTheIdlType) {
  // rbsim's publishers: a writer of the raw CDR sertype sends our bytes as they are (no
  // conversion on write), and a reader of the idlc type takes them, validates and decodes them.
  Loopback raw;
  ASSERT_NO_FATAL_FAILURE(raw.open(*tc_->desc, /*raw_writer=*/true));
  SerdataPtr ours(rbsim::node::make_raw_serdata(raw.raw_type(), ours_));
  ASSERT_NE(ours, nullptr);
  EXPECT_EQ(ddsi_serdata_size(ours.get()), ours_.size());
  const SerdataPtr got = raw.write_cdr(std::move(ours));
  ASSERT_NE(got, nullptr);
  EXPECT_NE(got->type, raw.raw_type()) << "the reader should hold the idlc type's sertype";
  EXPECT_TRUE(same_bytes(serialized(*got), ours_));
  Sample decoded(*tc_->desc);
  ASSERT_TRUE(ddsi_serdata_to_sample(got.get(), decoded.get(), nullptr, nullptr));
  const SerdataPtr again(ddsi_serdata_from_sample(got->type, SDK_DATA, decoded.get()));
  ASSERT_NE(again, nullptr);
  EXPECT_TRUE(same_bytes(serialized(*again), ours_));
}

std::string topic_param_name(const ::testing::TestParamInfo<TopicId>& info) {
  return std::string(rbsim::msgs::topic(info.param).suffix);
}

// The topics a World is encoded into (the commands are the controller's: tested below).
std::vector<TopicId> all_topics() {
  std::vector<TopicId> ids;
  for (const auto& t : rbsim::msgs::topics()) {
    if (!t.event) ids.push_back(t.id);
  }
  return ids;
}

INSTANTIATE_TEST_SUITE_P(AllTopics, CycloneCdr, ::testing::ValuesIn(all_topics()), topic_param_name);

// ---------------------------------------------------------------------------------------------

TEST(CycloneCdrCoverage, EveryTopicHasACaseAndItsDdsTypeName) {
  for (const auto& t : rbsim::msgs::topics()) {
    if (t.event) continue;  // CycloneCdrCommand below
    const TypeCase* c = find_case(t.id);
    ASSERT_NE(c, nullptr) << "no Cyclone comparison for topic " << t.suffix;
    EXPECT_EQ(rbsim::msgs::dds_type_name(t.type), c->desc->m_typename) << t.type;
    EXPECT_EQ(c->desc->m_nkeys, 0u) << t.type << ": ROS 2 message types are keyless";
  }
}

// rbsim_msgs/msg/Command (the node's /<ns>/commands): msgs::encode's bytes equal Cyclone's
// serialisation of the idlc-generated type filled with the same command.
TEST(CycloneCdrCommand, EncoderBytesEqualCycloneSerialisation) {
  rbsim::msgs::CommandMessage m;
  m.seq = 3;
  m.step = 1234;
  m.stamp = {1, 234000000};
  m.kind = rbsim::msgs::CommandMessage::SetParameters;
  m.source = "ros2 service";
  m.parameters = {{"forces.0.fy", rbsim::msgs::ParameterValue::of_double(-3.7)},
                  {"paused", rbsim::msgs::ParameterValue::of_bool(true)}};
  m.atomic = false;
  m.steps = 5;
  m.pause_seconds = 0.25;
  m.body = 2;
  m.jx = 0.5, m.jy = -2.0, m.px = 0.1, m.py = 1e-300;
  m.success = true;
  m.message = "set 2 of 2 parameters at step 1234";
  Bytes ours;
  rbsim::msgs::encode(m, ours);

  const dds_topic_descriptor_t& desc = rbsim_msgs_msg_dds__Command__desc;
  Sample sample(desc);
  auto& c = *static_cast<rbsim_msgs_msg_dds__Command_*>(sample.get());
  c.seq = m.seq;
  c.step = m.step;
  c.stamp = {m.stamp.sec, m.stamp.nanosec};
  c.kind = m.kind;
  c.source = str(m.source);
  auto* ps = alloc_seq(c.parameters, m.parameters.size());
  for (std::size_t k = 0; k < m.parameters.size(); ++k) {
    ps[k].name = str(m.parameters[k].name);
    ps[k].value.type = static_cast<std::uint8_t>(m.parameters[k].value.type);
    ps[k].value.bool_value = m.parameters[k].value.bool_value;
    ps[k].value.double_value = m.parameters[k].value.double_value;
    ps[k].value.string_value = str("");
  }
  c.atomic = m.atomic;
  c.steps = m.steps;
  c.pause_seconds = m.pause_seconds;
  c.body = m.body;
  c.jx = m.jx, c.jy = m.jy, c.px = m.px, c.py = m.py;
  c.success = m.success;
  c.message = str(m.message);
  Loopback dds;
  ASSERT_NO_FATAL_FAILURE(dds.open(desc));
  const SerdataPtr cyclone = dds.write_sample(sample.get());
  ASSERT_NE(cyclone, nullptr);
  EXPECT_TRUE(same_bytes(ours, serialized(*cyclone)));
}

// simulation_interfaces (the node's simulator services, rbsim/simulation_interfaces.hpp): the
// messages its replies and requests are made of, msgs::simulation::encode's bytes against Cyclone's
// serialisation of the idlc-generated types filled alike (nested types, a uint16 sequence, a
// sequence of one-byte structs, strings).
TEST(CycloneCdrSimulationInterfaces, EncoderBytesEqualCycloneSerialisation) {
  namespace sim = rbsim::msgs::simulation;
  const auto check = [](const dds_topic_descriptor_t& desc, const Sample& sample, const Bytes& ours) {
    Loopback dds;
    ASSERT_NO_FATAL_FAILURE(dds.open(desc));
    const SerdataPtr cyclone = dds.write_sample(sample.get());
    ASSERT_NE(cyclone, nullptr);
    EXPECT_TRUE(same_bytes(ours, serialized(*cyclone))) << desc.m_typename;
  };
  {
    sim::EntityState m;
    m.stamp = {12, 340000000};
    m.frame_id = "world";
    m.position = {1.5, -2.25, 0.0};
    m.orientation = rbsim::msgs::quaternion_z(0.7);
    m.linear_velocity = {0.1, 0.2, 0.0};
    m.angular_velocity = {0.0, 0.0, -0.3};
    m.linear_acceleration = {0.0, -9.81, 0.0};
    m.angular_acceleration = {0.0, 0.0, 1e-300};
    Bytes ours;
    sim::encode(m, ours);
    const dds_topic_descriptor_t& desc = simulation_interfaces_msg_dds__EntityState__desc;
    Sample sample(desc);
    auto& c = *static_cast<simulation_interfaces_msg_dds__EntityState_*>(sample.get());
    c.header.stamp = {m.stamp.sec, m.stamp.nanosec};
    c.header.frame_id = str(m.frame_id);
    c.pose.position = {m.position.x, m.position.y, m.position.z};
    c.pose.orientation = {m.orientation.x, m.orientation.y, m.orientation.z, m.orientation.w};
    const auto v3 = [](const sim::Vector3& v) { return geometry_msgs_msg_dds__Vector3_{v.x, v.y, v.z}; };
    c.twist.linear = v3(m.linear_velocity);
    c.twist.angular = v3(m.angular_velocity);
    c.acceleration.linear = v3(m.linear_acceleration);
    c.acceleration.angular = v3(m.angular_acceleration);
    check(desc, sample, ours);
  }
  {
    sim::EntityFilters m;
    m.filter = "^body_[0-9]+$";
    m.categories = {4, 1};
    m.tags.tags = {"wheel", ""};
    m.tags.filter_mode = 1;
    m.bounds.type = 3;
    m.bounds.points = {{1.0, 2.0, 3.0}, {0.5, 0.0, 0.0}};
    Bytes ours;
    sim::encode(m, ours);
    const dds_topic_descriptor_t& desc = simulation_interfaces_msg_dds__EntityFilters__desc;
    Sample sample(desc);
    auto& c = *static_cast<simulation_interfaces_msg_dds__EntityFilters_*>(sample.get());
    c.filter = str(m.filter);
    auto* cats = alloc_seq(c.categories, m.categories.size());
    for (std::size_t k = 0; k < m.categories.size(); ++k) cats[k].category = m.categories[k];
    auto* tags = alloc_seq(c.tags.tags, m.tags.tags.size());
    for (std::size_t k = 0; k < m.tags.tags.size(); ++k) tags[k] = str(m.tags.tags[k]);
    c.tags.filter_mode = m.tags.filter_mode;
    c.bounds.type = m.bounds.type;
    auto* points = alloc_seq(c.bounds.points, m.bounds.points.size());
    for (std::size_t k = 0; k < m.bounds.points.size(); ++k)
      points[k] = {m.bounds.points[k].x, m.bounds.points[k].y, m.bounds.points[k].z};
    check(desc, sample, ours);
  }
  {
    sim::SimulatorFeatures m;
    m.features = {5, 6, 8, 10, 12, 20, 24, 25, 26, 31, 32};
    m.spawn_formats = {"sdf"};
    m.custom_info = "rbsim";
    Bytes ours;
    sim::encode(m, ours);
    const dds_topic_descriptor_t& desc = simulation_interfaces_msg_dds__SimulatorFeatures__desc;
    Sample sample(desc);
    auto& c = *static_cast<simulation_interfaces_msg_dds__SimulatorFeatures_*>(sample.get());
    auto* f = alloc_seq(c.features, m.features.size());
    for (std::size_t k = 0; k < m.features.size(); ++k) f[k] = m.features[k];
    auto* formats = alloc_seq(c.spawn_formats, m.spawn_formats.size());
    formats[0] = str(m.spawn_formats[0]);
    c.custom_info = str(m.custom_info);
    check(desc, sample, ours);
  }
}

// type_description_interfaces (~/get_type_description, rbsim/type_description.hpp): a whole
// TypeDescription as msgs::type_description builds it (nested types, bounded names, default values,
// sequences of sequences) and a TypeSource, msgs::encode's bytes against Cyclone's serialisation of
// the idlc-generated types filled with the same values.
TEST(CycloneCdrTypeDescription, EncoderBytesEqualCycloneSerialisation) {
  namespace m = rbsim::msgs;
  const auto check = [](const dds_topic_descriptor_t& desc, const Sample& sample, const Bytes& ours) {
    Loopback dds;
    ASSERT_NO_FATAL_FAILURE(dds.open(desc));
    const SerdataPtr cyclone = dds.write_sample(sample.get());
    ASSERT_NE(cyclone, nullptr);
    EXPECT_TRUE(same_bytes(ours, serialized(*cyclone))) << desc.m_typename;
  };
  const auto fill = [](type_description_interfaces_msg_dds__IndividualTypeDescription_& c,
                       const m::IndividualTypeDescription& d) {
    std::snprintf(c.type_name, sizeof c.type_name, "%s", d.type_name.c_str());
    auto* fields = alloc_seq(c.fields, d.fields.size());
    for (std::size_t k = 0; k < d.fields.size(); ++k) {
      const m::Field& f = d.fields[k];
      fields[k].name = str(f.name);
      fields[k].type.type_id = f.type.type_id;
      fields[k].type.capacity = f.type.capacity;
      fields[k].type.string_capacity = f.type.string_capacity;
      std::snprintf(fields[k].type.nested_type_name, sizeof fields[k].type.nested_type_name, "%s",
                    f.type.nested_type_name.c_str());
      fields[k].default_value = str(f.default_value);
    }
  };
  {
    const auto td =
        m::type_description("rcl_interfaces/msg/ParameterDescriptor");  // defaults, bounded sequences
    ASSERT_TRUE(td.ok()) << td.error().message;
    ASSERT_FALSE(td.value().referenced_type_descriptions.empty());
    Bytes ours;
    m::encode(td.value(), ours);
    const dds_topic_descriptor_t& desc = type_description_interfaces_msg_dds__TypeDescription__desc;
    Sample sample(desc);
    auto& c = *static_cast<type_description_interfaces_msg_dds__TypeDescription_*>(sample.get());
    fill(c.type_description, td.value().type_description);
    const auto& refs = td.value().referenced_type_descriptions;
    auto* r = alloc_seq(c.referenced_type_descriptions, refs.size());
    for (std::size_t k = 0; k < refs.size(); ++k) fill(r[k], refs[k]);
    check(desc, sample, ours);
  }
  {
    const m::TypeSource source{"std_srvs/srv/Trigger", "srv", "---\nbool success\nstring message"};
    Bytes ours;
    m::encode(source, ours);
    const dds_topic_descriptor_t& desc = type_description_interfaces_msg_dds__TypeSource__desc;
    Sample sample(desc);
    auto& c = *static_cast<type_description_interfaces_msg_dds__TypeSource_*>(sample.get());
    c.type_name = str(source.type_name);
    c.encoding = str(source.encoding);
    c.raw_file_contents = str(source.raw_file_contents);
    check(desc, sample, ours);
  }
}

// The comparison itself must be able to fail: one altered byte, one ulp in one field of the C
// sample, and truncated data are all caught.
TEST(CycloneCdrSanity, AlteredBytesAndSamplesAreDetected) {
  Scene scene = test_scene();
  auto w = World::create(scene.world);
  ASSERT_TRUE(w.ok());
  for (int i = 0; i < kSteps; ++i) w->step();
  Bytes ours;
  rbsim::msgs::Encoder(scene).body_states(w.value(), ours);
  Loopback dds;
  ASSERT_NO_FATAL_FAILURE(dds.open(rbsim_msgs_msg_dds__BodyStates__desc));

  Sample exact(rbsim_msgs_msg_dds__BodyStates__desc);
  fill_body_states(scene, w.value(), exact.get());
  const SerdataPtr reference = dds.write_sample(exact.get());
  ASSERT_NE(reference, nullptr);
  const Bytes theirs = serialized(*reference);
  ASSERT_TRUE(same_bytes(ours, theirs));

  for (const std::size_t at : {std::size_t{1}, std::size_t{9}, ours.size() / 2, ours.size() - 1}) {
    Bytes bad = ours;
    bad[at] ^= std::byte{0x01};
    EXPECT_FALSE(same_bytes(bad, theirs)) << "flipped bit at byte " << at;
  }
  EXPECT_FALSE(same_bytes(std::span(ours).first(ours.size() - 1), theirs));

  Sample nudged(rbsim_msgs_msg_dds__BodyStates__desc);
  fill_body_states(scene, w.value(), nudged.get());
  auto& states = *static_cast<rbsim_msgs_msg_dds__BodyStates_*>(nudged.get());
  ASSERT_GE(states.bodies._length, 3u);
  states.bodies._buffer[2].theta = std::nextafter(states.bodies._buffer[2].theta, 10.0);
  const SerdataPtr changed = dds.write_sample(nudged.get());
  ASSERT_NE(changed, nullptr);
  EXPECT_FALSE(same_bytes(ours, serialized(*changed)));

  // Cyclone validates what it is given: a sequence length beyond the data is rejected.
  Bytes truncated(ours.begin(), ours.begin() + static_cast<std::ptrdiff_t>(ours.size() - 8));
  EXPECT_EQ(serdata_from_cdr(reference->type, truncated), nullptr);
  // and a decoded altered payload differs from the original sample.
  Bytes altered = ours;
  altered[ours.size() - 3] ^= std::byte{0x40};  // inside bodies[last].omega
  const SerdataPtr parsed = serdata_from_cdr(reference->type, altered);
  ASSERT_NE(parsed, nullptr);
  Sample decoded(rbsim_msgs_msg_dds__BodyStates__desc);
  ASSERT_TRUE(ddsi_serdata_to_sample(parsed.get(), decoded.get(), nullptr, nullptr));
  const auto& d = *static_cast<const rbsim_msgs_msg_dds__BodyStates_*>(decoded.get());
  const auto& e = *static_cast<const rbsim_msgs_msg_dds__BodyStates_*>(exact.get());
  ASSERT_EQ(d.bodies._length, e.bodies._length);
  EXPECT_NE(d.bodies._buffer[d.bodies._length - 1].omega, e.bodies._buffer[e.bodies._length - 1].omega);
  EXPECT_EQ(d.bodies._buffer[0].x, e.bodies._buffer[0].x);
}

// ---------------------------------------------------------------------------------------------
// Structural agreement of every generated type with its .msg, field by field, through idlc's
// serialisation op codes (one DDS_OP_ADR per member, in order, up to the first DDS_OP_RTS). The
// byte-identity tests above are the end-to-end check; this one pinpoints a disagreement.

struct MsgField {
  std::string type;  // base type as written: "float64", "Vector2", "std_msgs/Header"
  std::string name;
  enum class Array { None, Fixed, Sequence } array = Array::None;
};

std::vector<MsgField> msg_fields(std::string_view text) {
  std::vector<MsgField> fields;
  std::istringstream lines{std::string(text)};
  std::string line;
  while (std::getline(lines, line)) {
    if (const auto hash = line.find('#'); hash != std::string::npos) line.resize(hash);
    std::istringstream words(line);
    std::string type, name, third;
    if (!(words >> type >> name)) continue;
    if (name.find('=') != std::string::npos || ((words >> third) && third.starts_with('=')))
      continue;  // constant
    MsgField f;
    f.name = name;
    if (const auto bracket = type.find('['); bracket != std::string::npos) {
      const std::string inside = type.substr(bracket + 1, type.size() - bracket - 2);
      f.array =
          inside.empty() || inside.starts_with("<=") ? MsgField::Array::Sequence : MsgField::Array::Fixed;
      type.resize(bracket);
    }
    f.type = type;
    fields.push_back(f);
  }
  return fields;
}

struct Expected {
  std::uint32_t kind;   // DDS_OP_VAL_*
  std::uint32_t flags;  // DDS_OP_FLAG_SGN / DDS_OP_FLAG_FP
};

// How idlc encodes a .msg base type (nested messages: EXT as a member, STU inside sequences).
Expected expected_op(const std::string& type, bool element) {
  struct Prim {
    const char* name;
    Expected e;
  };
  static const Prim kPrims[] = {
      {"bool", {DDS_OP_VAL_BLN, 0}},
      {"byte", {DDS_OP_VAL_1BY, 0}},
      {"char", {DDS_OP_VAL_1BY, 0}},
      {"uint8", {DDS_OP_VAL_1BY, 0}},
      {"int8", {DDS_OP_VAL_1BY, DDS_OP_FLAG_SGN}},
      {"uint16", {DDS_OP_VAL_2BY, 0}},
      {"int16", {DDS_OP_VAL_2BY, DDS_OP_FLAG_SGN}},
      {"uint32", {DDS_OP_VAL_4BY, 0}},
      {"int32", {DDS_OP_VAL_4BY, DDS_OP_FLAG_SGN}},
      {"float32", {DDS_OP_VAL_4BY, DDS_OP_FLAG_FP}},
      {"uint64", {DDS_OP_VAL_8BY, 0}},
      {"int64", {DDS_OP_VAL_8BY, DDS_OP_FLAG_SGN}},
      {"float64", {DDS_OP_VAL_8BY, DDS_OP_FLAG_FP}},
      {"string", {DDS_OP_VAL_STR, 0}},
  };
  for (const Prim& p : kPrims) {
    if (type == p.name) return p.e;
  }
  if (type.starts_with("string<=")) return {DDS_OP_VAL_BST, 0};  // msg2idl: string<N>
  return {element ? std::uint32_t{DDS_OP_VAL_STU} : std::uint32_t{DDS_OP_VAL_EXT}, 0};
}

// Words taken by one DDS_OP_ADR instruction (the kinds idlc emits for final structs).
std::size_t adr_length(std::uint32_t op) {
  const auto type = static_cast<std::uint32_t>(DDS_OP_TYPE(op));
  const auto sub = static_cast<std::uint32_t>(DDS_OP_SUBTYPE(op));
  const bool sub_complex = sub == DDS_OP_VAL_STU || sub == DDS_OP_VAL_UNI || sub == DDS_OP_VAL_SEQ ||
                           sub == DDS_OP_VAL_BSQ || sub == DDS_OP_VAL_ARR;
  switch (type) {
    case DDS_OP_VAL_EXT:
      return 3;
    case DDS_OP_VAL_BST:
      return 3;
    case DDS_OP_VAL_SEQ:
      return sub_complex ? 4 : (sub == DDS_OP_VAL_BST || sub == DDS_OP_VAL_ENU ? 3 : 2);
    case DDS_OP_VAL_BSQ:
      return sub_complex ? 5 : (sub == DDS_OP_VAL_BST || sub == DDS_OP_VAL_ENU ? 4 : 3);
    case DDS_OP_VAL_ARR:
      return sub_complex ? 5 : (sub == DDS_OP_VAL_BST || sub == DDS_OP_VAL_ENU ? 4 : 3);
    default:
      return 2;
  }
}

TEST(GeneratedIdl, EveryMsgTypeHasAGeneratedType) {
  std::vector<std::string> generated;
  for (const auto& g : rbsim_dds_test::kGeneratedTypes) generated.emplace_back(g.ros_type);
  std::vector<std::string> defined;
  for (std::string_view t : rbsim::msgs::definition_types()) defined.emplace_back(t);
  std::sort(generated.begin(), generated.end());
  std::sort(defined.begin(), defined.end());
  EXPECT_EQ(generated, defined);
}

TEST(GeneratedIdl, MatchesTheMsgFieldByField) {
  for (const auto& g : rbsim_dds_test::kGeneratedTypes) {
    SCOPED_TRACE(g.ros_type);
    EXPECT_EQ(rbsim::msgs::dds_type_name(g.ros_type), g.desc->m_typename);
    const std::string_view text = rbsim::msgs::definition(g.ros_type);
    ASSERT_FALSE(text.empty());
    const std::vector<MsgField> fields = msg_fields(text);
    const std::uint32_t* op = g.desc->m_ops;
    const std::uint32_t* const end = g.desc->m_ops + g.desc->m_nops * 8;  // generous bound
    std::size_t members = 0;
    for (; op < end && DDS_OP(*op) != DDS_OP_RTS; op += adr_length(*op), ++members) {
      ASSERT_EQ(DDS_OP(*op), DDS_OP_ADR) << "member " << members << ": unexpected instruction";
      if (members >= fields.size()) continue;
      const MsgField& f = fields[members];
      SCOPED_TRACE(f.name);
      const auto type = static_cast<std::uint32_t>(DDS_OP_TYPE(*op));
      const std::uint32_t flags = DDS_OP_FLAGS(*op) & (DDS_OP_FLAG_SGN | DDS_OP_FLAG_FP);
      if (f.array == MsgField::Array::None) {
        const Expected e = expected_op(f.type, false);
        EXPECT_EQ(type, e.kind);
        EXPECT_EQ(flags, e.flags);
      } else {
        const Expected e = expected_op(f.type, true);
        EXPECT_EQ(type, f.array == MsgField::Array::Sequence ? std::uint32_t{DDS_OP_VAL_SEQ}
                                                             : std::uint32_t{DDS_OP_VAL_ARR});
        EXPECT_EQ(static_cast<std::uint32_t>(DDS_OP_SUBTYPE(*op)), e.kind);
        EXPECT_EQ(flags, e.flags);
      }
    }
    // A message of constants only (rcl_interfaces/msg/ParameterType) gets rosidl's one placeholder
    // member (msg2idl writes it, as rosidl's IDL does).
    EXPECT_EQ(members, fields.empty() ? 1 : fields.size()) << "member count: generated vs .msg";
  }
}

}  // namespace
