// The viewer-ready topics: triangulation of body hulls, the z-rotation quaternion, /tf, the springs
// marker and the latched markers (decoded back by the schema decoder and the typed decoders), the
// --topics selection, and EnergyTerms' potential split (with recordings made before it).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "decoder_for.hpp"
#include "rbsim/builders.hpp"
#include "rbsim/msgs.hpp"

namespace {

using rbsim::Vec2;
using rbsim::msgs::Scalar;
using rbsim::msgs::TopicId;

double cross(const Vec2& a, const Vec2& b) {
  return a.x() * b.y() - a.y() * b.x();
}
double polygon_area(const std::vector<Vec2>& p) {
  double a = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) a += 0.5 * cross(p[i], p[(i + 1) % p.size()]);
  return std::fabs(a);
}
bool inside(const std::vector<Vec2>& p, const Vec2& q) {  // even-odd rule
  bool in = false;
  for (std::size_t i = 0, j = p.size() - 1; i < p.size(); j = i++) {
    if ((p[i].y() > q.y()) != (p[j].y() > q.y()) &&
        q.x() < (p[j].x() - p[i].x()) * (q.y() - p[i].y()) / (p[j].y() - p[i].y()) + p[i].x())
      in = !in;
  }
  return in;
}

// Triangles tile the polygon: n - 2 of them, each counter-clockwise with its centroid (and the
// midpoints of its edges moved slightly inwards) inside the polygon, areas summing to its area.
void expect_tiles(const std::vector<Vec2>& polygon, std::size_t expected_triangles) {
  const std::vector<std::uint32_t> t = rbsim::msgs::triangulate(polygon);
  ASSERT_EQ(t.size() % 3, 0u);
  EXPECT_EQ(t.size() / 3, expected_triangles);
  double sum = 0.0;
  for (std::size_t k = 0; k < t.size(); k += 3) {
    ASSERT_LT(std::max({t[k], t[k + 1], t[k + 2]}), polygon.size());
    const Vec2 &a = polygon[t[k]], &b = polygon[t[k + 1]], &c = polygon[t[k + 2]];
    const double area = 0.5 * cross(b - a, c - a);
    EXPECT_GT(area, 0.0) << "triangle " << k / 3 << " is not counter-clockwise";
    const Vec2 centroid = (a + b + c) / 3.0;
    EXPECT_TRUE(inside(polygon, centroid)) << "triangle " << k / 3;
    for (const auto& [p, q] : {std::pair{a, b}, std::pair{b, c}, std::pair{c, a}}) {
      EXPECT_TRUE(inside(polygon, 0.5 * (p + q) + 1e-6 * (centroid - 0.5 * (p + q))));
    }
    sum += area;
  }
  EXPECT_NEAR(sum, polygon_area(polygon), 1e-12 * polygon_area(polygon));
}

std::vector<Vec2> star(int points, double outer, double inner) {
  std::vector<Vec2> p;
  for (int i = 0; i < 2 * points; ++i) {
    const double r = i % 2 == 0 ? outer : inner, a = std::numbers::pi * i / points;
    p.emplace_back(r * std::sin(a), r * std::cos(a));
  }
  return p;
}

// A crescent: an outer arc and an inner arc of a circle shifted sideways.
std::vector<Vec2> crescent(int n) {
  std::vector<Vec2> p;
  for (int i = 0; i <= n; ++i) {
    const double a = -0.5 * std::numbers::pi + std::numbers::pi * i / n;
    p.emplace_back(std::cos(a), std::sin(a));
  }
  for (int i = n - 1; i >= 1; --i) {
    const double a = -0.4 * std::numbers::pi + 0.8 * std::numbers::pi * i / n;
    p.emplace_back(0.45 * std::cos(a) + 0.2, 0.95 * std::sin(a));
  }
  return p;
}

TEST(Triangulate, ConvexPolygonsBothWindings) {
  std::vector<Vec2> square = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  expect_tiles(square, 2);
  std::reverse(square.begin(), square.end());
  expect_tiles(square, 2);
  std::vector<Vec2> hexagon;
  for (int i = 0; i < 6; ++i)
    hexagon.emplace_back(std::cos(i * std::numbers::pi / 3), std::sin(i * std::numbers::pi / 3));
  expect_tiles(hexagon, 4);
}

TEST(Triangulate, ConcaveStarsAndCrescentsBothWindings) {
  for (std::vector<Vec2> p : {star(5, 1.0, 0.45), star(7, 2.0, 0.5), crescent(12), crescent(30)}) {
    expect_tiles(p, p.size() - 2);
    std::reverse(p.begin(), p.end());  // rbsim's hulls are clockwise
    expect_tiles(p, p.size() - 2);
  }
}

TEST(Triangulate, DegenerateInputs) {
  EXPECT_TRUE(rbsim::msgs::triangulate(std::vector<Vec2>{{0, 0}, {1, 0}}).empty());
  // A straight vertex adds no triangle; the rest still tiles.
  expect_tiles({{0, 0}, {1, 0}, {2, 0}, {2, 1}, {0, 1}}, 3);
}

TEST(Quaternion, RotatesAboutZ) {
  for (double theta : {0.0, 0.3, -1.2, std::numbers::pi, 5.0}) {
    const auto q = rbsim::msgs::quaternion_z(theta);
    EXPECT_EQ(q.x, 0.0);
    EXPECT_EQ(q.y, 0.0);
    EXPECT_NEAR(q.z * q.z + q.w * q.w, 1.0, 1e-15);
    // Rotating (1, 0, 0) by q: x' = 1 - 2 z^2, y' = 2 w z.
    EXPECT_NEAR(1.0 - 2.0 * q.z * q.z, std::cos(theta), 1e-15);
    EXPECT_NEAR(2.0 * q.w * q.z, std::sin(theta), 1e-15);
  }
}

rbsim::Scene scene_with_anchor() {
  rbsim::Scene scene;
  scene.name = "viewer";
  scene.world = rbsim::builders::grid(3, /*wind_and_springs=*/true);
  scene.world.springs.front().body_i = rbsim::kFixed;  // its end i now fixed in world space
  for (int b = 0; b < 3; ++b) scene.body_colors.push_back(rbsim::default_body_color(b));
  for (std::size_t k = 0; k < scene.world.springs.size(); ++k)
    scene.spring_colors.push_back(rbsim::Color{0.1 * static_cast<double>(k + 1), 0.5, 0.25});
  scene.duration = 1.0;
  return scene;
}

TEST(EncoderTf, OneTransformPerBodyInItsNamespacedFrame) {
  const rbsim::Scene scene = scene_with_anchor();
  auto w = rbsim::World::create(scene.world);
  ASSERT_TRUE(w.ok());
  for (int i = 0; i < 40; ++i) w->step();
  rbsim::msgs::Bytes out;
  rbsim::msgs::Encoder(scene, "/robots/arm/").tf(w.value(), out);
  std::vector<Scalar> v;
  ASSERT_TRUE(decoder_for(TopicId::Tf).decode(out, v).ok());
  ASSERT_EQ(v[0].u, 3u);
  rbsim::msgs::TfMessage tf;
  ASSERT_TRUE(rbsim::msgs::decode_tf(out, tf).ok());
  ASSERT_EQ(tf.transforms.size(), 3u);
  const rbsim::msgs::Time stamp = rbsim::msgs::sim_time(w.value());
  for (int b = 0; b < 3; ++b) {
    const auto& t = tf.transforms[static_cast<std::size_t>(b)];
    EXPECT_EQ(t.frame_id, "world");
    EXPECT_EQ(t.child_frame_id, "robots/arm/body_" + std::to_string(b));
    EXPECT_EQ(t.stamp.sec, stamp.sec);
    EXPECT_EQ(t.stamp.nanosec, stamp.nanosec);
    EXPECT_EQ(t.x, w->x()[b]);
    EXPECT_EQ(t.y, w->y()[b]);
    EXPECT_EQ(t.z, 0.0);
    EXPECT_NEAR(2.0 * std::atan2(t.qz, t.qw), w->theta()[b], 1e-12);
  }
  for (std::size_t n = 0; n < out.size() - 3; ++n)
    EXPECT_FALSE(rbsim::msgs::decode_tf(std::span(out).first(n), tf).ok()) << n;
  EXPECT_EQ(rbsim::msgs::body_frame("rbsim", 4), "rbsim/body_4");
  EXPECT_EQ(rbsim::msgs::body_frame("", 0), "body_0");
}

TEST(EncoderSprings, LineListOfTheSpringEndsInSceneColours) {
  const rbsim::Scene scene = scene_with_anchor();
  auto w = rbsim::World::create(scene.world);
  ASSERT_TRUE(w.ok());
  for (int i = 0; i < 25; ++i) w->step();
  rbsim::msgs::Bytes out;
  rbsim::msgs::Encoder(scene).springs(w.value(), out);
  std::vector<Scalar> v;
  ASSERT_TRUE(decoder_for(TopicId::Springs).decode(out, v).ok());
  rbsim::msgs::MarkerMessage m;
  ASSERT_TRUE(rbsim::msgs::decode_marker(out, m).ok());
  EXPECT_EQ(m.frame_id, "world");
  EXPECT_EQ(m.type, rbsim::msgs::kMarkerLineList);
  const std::size_t n = static_cast<std::size_t>(w->spring_count());
  ASSERT_EQ(m.points.size(), 2 * n);
  ASSERT_EQ(m.colors.size(), 2 * n);
  for (std::size_t k = 0; k < n; ++k) {
    const rbsim::SpringState st = w->spring_state(rbsim::SpringId{static_cast<std::int32_t>(k)});
    EXPECT_EQ(m.points[2 * k], st.end_i);
    EXPECT_EQ(m.points[2 * k + 1], st.end_j);
    EXPECT_EQ(m.colors[2 * k][0], static_cast<float>(scene.spring_colors[k].r));
  }
}

// Springs that share one colour: it is the marker's color, with no per-vertex colours (32 bytes
// less per spring); the points are as before.
TEST(EncoderSprings, OneColourForEverySpringIsTheMarkersColor) {
  rbsim::Scene scene = scene_with_anchor();
  const rbsim::Color shared{0.2, 0.4, 0.6};
  scene.spring_colors.assign(scene.world.springs.size(), shared);
  auto w = rbsim::World::create(scene.world);
  ASSERT_TRUE(w.ok());
  for (int i = 0; i < 25; ++i) w->step();
  rbsim::msgs::Bytes one, each;
  rbsim::msgs::Encoder(scene).springs(w.value(), one);
  rbsim::msgs::Encoder(scene_with_anchor()).springs(w.value(), each);
  rbsim::msgs::MarkerMessage m, per_vertex;
  ASSERT_TRUE(rbsim::msgs::decode_marker(one, m).ok());
  ASSERT_TRUE(rbsim::msgs::decode_marker(each, per_vertex).ok());
  const std::size_t n = static_cast<std::size_t>(w->spring_count());
  ASSERT_GT(n, 1u);
  EXPECT_TRUE(m.colors.empty());
  EXPECT_EQ(m.color[0], static_cast<float>(shared.r));
  EXPECT_EQ(m.color[1], static_cast<float>(shared.g));
  EXPECT_EQ(m.color[2], static_cast<float>(shared.b));
  EXPECT_EQ(m.color[3], 1.0f);
  EXPECT_EQ(m.points, per_vertex.points);
  EXPECT_EQ(each.size() - one.size(), 2 * n * 16);  // 2 n RGBA float colours
}

TEST(EncoderMarkers, FilledHullsOutlinesAndAnchorsInTheirFrames) {
  const rbsim::Scene scene = scene_with_anchor();
  auto w = rbsim::World::create(scene.world);
  ASSERT_TRUE(w.ok());
  rbsim::msgs::Bytes out;
  rbsim::msgs::Encoder(scene).markers(w.value(), out);
  std::vector<Scalar> v;
  ASSERT_TRUE(decoder_for(TopicId::Markers).decode(out, v).ok());
  std::vector<rbsim::msgs::MarkerMessage> ms;
  ASSERT_TRUE(rbsim::msgs::decode_marker_array(out, ms).ok());
  ASSERT_EQ(ms.size(), 2u * 3u + 1u);
  for (std::int32_t b = 0; b < 3; ++b) {
    const auto& fill = ms[2 * static_cast<std::size_t>(b)];
    const auto& line = ms[2 * static_cast<std::size_t>(b) + 1];
    const auto hull = w->hull(rbsim::BodyId{b});
    for (const auto* m : {&fill, &line}) {
      EXPECT_EQ(m->frame_id, "rbsim/body_" + std::to_string(b));
      EXPECT_TRUE(m->frame_locked);
      EXPECT_EQ(m->lifetime.sec, 0);
      EXPECT_EQ(m->color[0], static_cast<float>(scene.body_colors[static_cast<std::size_t>(b)].r));
    }
    EXPECT_EQ(fill.type, rbsim::msgs::kMarkerTriangleList);
    EXPECT_EQ(fill.points.size(), 3 * (hull.size() - 2));
    double area = 0.0;
    for (std::size_t k = 0; k + 2 < fill.points.size(); k += 3) {
      area += 0.5 * cross(fill.points[k + 1] - fill.points[k], fill.points[k + 2] - fill.points[k]);
    }
    EXPECT_NEAR(area, polygon_area({hull.begin(), hull.end()}), 1e-12);
    EXPECT_EQ(line.type, rbsim::msgs::kMarkerLineStrip);
    ASSERT_EQ(line.points.size(), hull.size() + 1);
    EXPECT_EQ(line.points.front(), line.points.back());
    EXPECT_EQ(line.scale_x, 2.0 * w->radius(rbsim::BodyId{b}));
  }
  const auto& anchors = ms.back();
  EXPECT_EQ(anchors.frame_id, "world");
  EXPECT_EQ(anchors.type, rbsim::msgs::kMarkerSphereList);
  std::vector<Vec2> fixed;
  for (const rbsim::SpringDef& sp : scene.world.springs) {
    if (sp.body_i == rbsim::kFixed) fixed.push_back(sp.anchor_i);
    if (sp.body_j == rbsim::kFixed) fixed.push_back(sp.anchor_j);
  }
  ASSERT_GE(fixed.size(), 1u);
  EXPECT_EQ(anchors.points, fixed);
  ASSERT_EQ(anchors.colors.size(), fixed.size());
}

TEST(TopicSet, DefaultIsEverythingButPoses) {
  const rbsim::msgs::TopicSet d = rbsim::msgs::default_topics();
  for (const auto& spec : rbsim::msgs::topics()) {
    EXPECT_EQ(d.test(static_cast<std::size_t>(spec.id)), spec.id != TopicId::Poses && !spec.event)
        << spec.suffix;
  }
  EXPECT_TRUE(rbsim::msgs::topic(TopicId::Markers).transient_local);
  EXPECT_FALSE(rbsim::msgs::topic(TopicId::Markers).per_step);
  EXPECT_EQ(rbsim::msgs::topic_name(rbsim::msgs::topic(TopicId::Tf), "rbsim"), "/tf");
  EXPECT_EQ(rbsim::msgs::topic_name(rbsim::msgs::topic(TopicId::Springs), "ns"), "/ns/springs");
}

TEST(TopicSet, ParsesNamesInEveryForm) {
  const auto set = rbsim::msgs::parse_topic_set("poses, /tf,rbsim/springs,/rbsim/body_states,clock");
  ASSERT_TRUE(set.ok()) << set.error().message;
  const std::vector<TopicId> want = {TopicId::SceneDescription, TopicId::BodyStates, TopicId::Tf,
                                     TopicId::Springs,          TopicId::Clock,      TopicId::Poses};
  EXPECT_EQ(rbsim::msgs::topic_ids(set.value()), want);  // scene always, topics() order
  const auto tf = rbsim::msgs::parse_topic_set("tf");
  ASSERT_TRUE(tf.ok());
  EXPECT_EQ(tf.value().count(), 2u);
  const auto other_ns = rbsim::msgs::parse_topic_set("/robots/markers", "robots");
  ASSERT_TRUE(other_ns.ok());
  EXPECT_TRUE(other_ns.value().test(static_cast<std::size_t>(TopicId::Markers)));
}

TEST(TopicSet, RejectsUnknownNamesListingTheValidOnes) {
  for (const char* bad : {"body_state", "tf,bogus", "/other/body_states", "", " , "}) {
    const auto set = rbsim::msgs::parse_topic_set(bad);
    ASSERT_FALSE(set.ok()) << bad;
    if (std::string_view(bad).find_first_not_of(" ,") != std::string_view::npos) {
      EXPECT_NE(set.error().message.find("unknown topic"), std::string::npos) << set.error().message;
      EXPECT_NE(
          set.error().message.find("(topics: /clock, /rbsim/body_states, /rbsim/energy, /rbsim/markers, "
                                   "/rbsim/poses, /rbsim/scene, /rbsim/spring_states, /rbsim/springs, /tf)"),
          std::string::npos)
          << set.error().message;
    }
  }
}

TEST(EnergyTermsSplit, TotalsAndTheLayoutBeforeThem) {
  const rbsim::Scene scene = scene_with_anchor();
  auto w = rbsim::World::create(scene.world);
  ASSERT_TRUE(w.ok());
  for (int i = 0; i < 30; ++i) w->step();
  rbsim::msgs::Bytes out;
  rbsim::msgs::Encoder(scene).energy(w.value(), out);
  rbsim::msgs::EnergyTermsMessage m;
  ASSERT_TRUE(rbsim::msgs::decode_energy_terms(out, m).ok());
  const rbsim::Energy e = w->energy();
  EXPECT_TRUE(m.has_split);
  EXPECT_EQ(m.potential_gravity, e.u_gravity);
  EXPECT_EQ(m.potential_spring, e.u_spring);
  EXPECT_NEAR(m.potential_gravity + m.potential_spring, m.potential, 1e-12 * std::fabs(m.potential));

  // The old layout is the new one without the two trailing float64s (no padding after them).
  auto schema = rbsim::msgs::ros2msg_schema("rbsim_msgs/msg/EnergyTerms");
  ASSERT_TRUE(schema.ok());
  EXPECT_EQ(rbsim::msgs::energy_terms_version(schema.value()), rbsim::msgs::EnergyTermsVersion::Current);
  std::string old = schema.value();
  const auto split = old.find("float64 potential_gravity");
  ASSERT_NE(split, std::string::npos);
  old.erase(split, old.find('\n', old.find("float64 potential_spring")) + 1 - split);
  EXPECT_EQ(rbsim::msgs::energy_terms_version(old), rbsim::msgs::EnergyTermsVersion::WithoutSplit);
  EXPECT_FALSE(rbsim::msgs::energy_terms_version(old + "float64 extra\n").has_value());
  const std::span<const std::byte> before(out.data(), out.size() - 16);
  EXPECT_FALSE(rbsim::msgs::decode_energy_terms(before, m).ok());
  rbsim::msgs::EnergyTermsMessage o;
  ASSERT_TRUE(
      rbsim::msgs::decode_energy_terms(before, o, rbsim::msgs::EnergyTermsVersion::WithoutSplit).ok());
  EXPECT_FALSE(o.has_split);
  EXPECT_EQ(o.total, m.total);
  EXPECT_EQ(o.potential_gravity, 0.0);
}

}  // namespace
