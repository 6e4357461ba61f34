// load_scene / parse_scene on the public FOSSSim scenes and on the dialect's quirks.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "rbsim/scene.hpp"

namespace rbsim {
namespace {

namespace fs = std::filesystem;
const std::string kData = RBSIM_TEST_DATA_DIR;
const std::string kScenes = kData + "/fosssim/scenes";

std::vector<std::string> public_scenes() {
  std::vector<std::string> out;
  for (const auto& e : fs::recursive_directory_iterator(kScenes)) {
    if (e.is_regular_file() && e.path().extension() == ".xml") out.push_back(e.path().string());
  }
  std::sort(out.begin(), out.end());
  return out;
}

Scene parse_ok(const std::string& text, const std::string& path = "mem.xml") {
  Result<Scene> s = parse_scene(text, path);
  if (!s) ADD_FAILURE() << "unexpected error: " << s.error().message;
  return s ? std::move(s.value()) : Scene{};
}

// A minimal valid scene around `body` (which follows four vertices forming a 2 x 2 square).
std::string scene_with(const std::string& extra) {
  return "<scene>\n"
         "  <simtype type=\"rigid-body\"/>\n"
         "  <duration time=\"1.0\"/>\n"
         "  <rigidbodyintegrator type=\"explicit-euler\" dt=\"0.01\"/>\n"
         "  <rigidbodyvertex x=\"-1\" y=\"-1\" m=\"1\"/>\n"
         "  <rigidbodyvertex x=\"-1\" y=\"1\" m=\"1\"/>\n"
         "  <rigidbodyvertex x=\"1\" y=\"1\" m=\"1\"/>\n"
         "  <rigidbodyvertex x=\"1\" y=\"-1\" m=\"1\"/>\n" +
         extra + "</scene>\n";
}

TEST(LoadScene, EveryPublicSceneLoads) {
  const auto scenes = public_scenes();
  ASSERT_EQ(scenes.size(), 40u) << "expected the 40 public scenes under " << kScenes;
  std::vector<std::string> groups;
  for (const std::string& path : scenes) {
    SCOPED_TRACE(path);
    Result<Scene> s = load_scene(path);
    ASSERT_TRUE(s) << s.error().message;
    EXPECT_EQ(s->path, path);
    EXPECT_EQ(s->name, fs::path(path).stem().string());
    EXPECT_TRUE(s->warnings.empty()) << s->warnings.front();
    EXPECT_FALSE(s->description.empty());
    EXPECT_GE(s->world.bodies.size(), 1u);
    EXPECT_GT(s->duration, 0.0);
    EXPECT_GT(s->step_count(), 0);
    EXPECT_EQ(s->body_colors.size(), s->world.bodies.size());
    EXPECT_EQ(s->spring_colors.size(), s->world.springs.size());
    // the file name says which integrator the scene uses
    const std::string name = s->name;
    if (name.ends_with("ee")) {
      EXPECT_EQ(s->world.integrator, Integrator::ExplicitEuler);
    }
    if (name.ends_with("sym")) {
      EXPECT_EQ(s->world.integrator, Integrator::SymplecticEuler);
    }
    // every body is a proper hull with positive masses, and the world accepts the definition
    for (const BodyDef& b : s->world.bodies) {
      EXPECT_GE(b.hull.size(), 2u);
      EXPECT_EQ(b.hull.size(), b.masses.size());
    }
    EXPECT_TRUE(World::create(s->world).ok());
    groups.push_back(fs::path(path).parent_path().filename().string());
  }
  groups.erase(std::unique(groups.begin(), groups.end()), groups.end());
  EXPECT_EQ(groups, (std::vector<std::string>{"gravitytests", "hollistictests", "inertiatests", "notests",
                                              "springtests", "windtests"}));
}

TEST(LoadScene, PublicSceneContentsAreReadCorrectly) {
  Result<Scene> g = load_scene(kScenes + "/gravitytests/test00ee.xml");
  ASSERT_TRUE(g) << g.error().message;
  EXPECT_EQ(g->world.integrator, Integrator::ExplicitEuler);
  EXPECT_EQ(g->world.dt, 0.01);
  EXPECT_EQ(g->duration, 4.0);
  EXPECT_EQ(g->step_count(), 400);
  ASSERT_EQ(g->world.bodies.size(), 1u);
  EXPECT_EQ(g->world.bodies[0].hull,
            (std::vector<Vec2>{{-1.0, -1.0}, {-1.0, 1.0}, {1.0, 1.0}, {1.0, -1.0}}));  // " 1.0" parsed
  ASSERT_TRUE(g->viewport.has_value());
  EXPECT_EQ(g->viewport->cx, 8.0);
  EXPECT_EQ(g->viewport->size, 9.1);
  ASSERT_EQ(g->world.gravity.size(), 1u);

  Result<Scene> w = load_scene(kScenes + "/windtests/test00ee.xml");
  ASSERT_TRUE(w) << w.error().message;
  EXPECT_EQ(w->world.bodies.size(), 4u);
  ASSERT_EQ(w->world.winds.size(), 1u);
  EXPECT_EQ(w->world.winds[0].beta, 1.0);
  EXPECT_EQ(w->world.winds[0].velocity, Vec2(1.0, 0.0));
  EXPECT_EQ(w->world.winds[0].points_per_edge, 2);
  EXPECT_EQ(w->duration, 21.0);
  EXPECT_EQ(w->world.bodies[3].hull[1], Vec2(-1.0, 12.0));

  Result<Scene> sp = load_scene(kScenes + "/springtests/test02sym.xml");
  ASSERT_TRUE(sp) << sp.error().message;
  ASSERT_EQ(sp->world.springs.size(), 1u);
  const SpringDef& s = sp->world.springs[0];
  EXPECT_EQ(s.body_i, 0);
  EXPECT_EQ(s.anchor_i, Vec2(1.0, 1.0));
  EXPECT_EQ(s.body_j, 1);
  EXPECT_EQ(s.anchor_j, Vec2(-1.0, 1.0));
  EXPECT_EQ(s.stiffness, 1.0);
  EXPECT_EQ(s.rest_length, 4.0);
  ASSERT_TRUE(sp->max_sim_freq.has_value());
  EXPECT_EQ(*sp->max_sim_freq, 5000.0);
}

TEST(LoadScene, PublicSceneColoursAreApplied) {
  Result<Scene> c = load_scene(kScenes + "/hollistictests/cantilever.xml");
  ASSERT_TRUE(c) << c.error().message;
  ASSERT_EQ(c->body_colors.size(), 5u);
  EXPECT_EQ(c->body_colors[1].r, 0.0);
  EXPECT_EQ(c->body_colors[1].g, 0.4);
  EXPECT_EQ(c->body_colors[1].b, 0.0);
  EXPECT_EQ(c->body_colors[2].b, 0.8);
  ASSERT_GT(c->spring_colors.size(), 4u);
  EXPECT_EQ(c->spring_colors[4].r, 0.2);
  EXPECT_EQ(c->spring_colors[4].b, 0.8);
  // the first spring of the cantilever is fixed at one end (i = -1)
  EXPECT_EQ(c->world.springs[0].body_i, kFixed);
  EXPECT_EQ(c->world.springs[0].body_j, 0);
}

TEST(ParseScene, RepeatedPAttributesKeepDocumentOrder) {
  const Scene s = parse_ok(
      scene_with("  <rigidbody p=\"2\" p=\"0\" p=\"3\" vx=\"0\" vy=\"0\" omega=\"0\" r=\"0.1\" p=\"1\"/>\n"));
  ASSERT_EQ(s.world.bodies.size(), 1u);
  EXPECT_EQ(s.world.bodies[0].hull, (std::vector<Vec2>{{1.0, 1.0}, {-1.0, -1.0}, {1.0, -1.0}, {-1.0, 1.0}}));
}

TEST(ParseScene, VerticesAreOneGlobalListAndBodiesMayReferAhead) {
  const Scene s = parse_ok(
      scene_with("  <rigidbody p=\"4\" p=\"5\" vx=\"0\" vy=\"0\" omega=\"0\" r=\"0.1\"/>\n"
                 "  <rigidbodyvertex x=\"5\" y=\"0\" m=\"2\"/>\n"
                 "  <rigidbodyvertex x=\"7\" y=\"0\" m=\"3\"/>\n"
                 "  <rigidbody p=\"0\" p=\"1\" p=\"2\" p=\"3\" vx=\"0\" vy=\"0\" omega=\"0\" r=\"0.1\"/>\n"));
  ASSERT_EQ(s.world.bodies.size(), 2u);
  EXPECT_EQ(s.world.bodies[0].hull, (std::vector<Vec2>{{5.0, 0.0}, {7.0, 0.0}}));
  EXPECT_EQ(s.world.bodies[0].masses, (std::vector<double>{2.0, 3.0}));
  EXPECT_EQ(s.world.bodies[1].hull.size(), 4u);
}

TEST(ParseScene, NumbersMayCarrySpacesAndSigns) {
  const Scene s = parse_ok(
      scene_with("  <rigidbodyvertex x=\"  2.5 \" y=\"\t-3\" m=\" 1e1\"/>\n"
                 "  <rigidbody p=\" 0\" p=\"4 \" vx=\"+1.5\" vy=\" -0.25 \" omega=\" 2\" r=\" 0.1\"/>\n"));
  ASSERT_EQ(s.world.bodies.size(), 1u);
  const BodyDef& b = s.world.bodies[0];
  EXPECT_EQ(b.hull[1], Vec2(2.5, -3.0));
  EXPECT_EQ(b.masses[1], 10.0);
  EXPECT_EQ(b.velocity, Vec2(1.5, -0.25));
  EXPECT_EQ(b.omega, 2.0);
  EXPECT_EQ(b.radius, 0.1);
}

TEST(ParseScene, ReadsEveryNodeKind) {
  const Scene s = parse_ok(
      scene_with("  <rigidbody p=\"0\" p=\"1\" p=\"2\" p=\"3\" vx=\"1\" vy=\"2\" omega=\"-0.5\" r=\"0.3\"/>\n"
                 "  <rigidbody p=\"1\" p=\"2\" vx=\"0\" vy=\"0\" omega=\"0\" r=\"0.1\"/>\n"
                 "  <rigidbodyspringforce i=\"0\" pix=\"1\" piy=\"2\" j=\"-1\" pjx=\"3\" pjy=\"4\" k=\"5\" "
                 "l0=\"6\"/>\n"
                 "  <rigidbodyspringforce i=\"-1\" pix=\"0\" piy=\"0\" j=\"1\" pjx=\"0\" pjy=\"0\" k=\"0\" "
                 "l0=\"0\"/>\n"
                 "  <rigidbodygravityforce fx=\"0.5\" fy=\"-9.81\"/>\n"
                 "  <rigidbodygravityforce fx=\"1\" fy=\"0\"/>\n"
                 "  <rigidbodywindforce beta=\"0.5\" fx=\"2\" fy=\"-1\" pointsperedge=\"7\"/>\n"
                 "  <description text=\"hello world\"/>\n"
                 "  <scenetag tag=\"RigidBody\"/>\n"
                 "  <viewport cx=\"1\" cy=\"2\" size=\"3\"/>\n"
                 "  <maxsimfreq max=\"100\"/>\n"
                 "  <backgroundcolor r=\"0\" g=\"0.5\" b=\"1\"/>\n"),
      "dir/some.scene.xml");
  EXPECT_EQ(s.name, "some.scene");
  EXPECT_EQ(s.path, "dir/some.scene.xml");
  EXPECT_EQ(s.world.integrator, Integrator::ExplicitEuler);
  ASSERT_EQ(s.world.bodies.size(), 2u);
  EXPECT_EQ(s.world.bodies[0].velocity, Vec2(1.0, 2.0));
  EXPECT_EQ(s.world.bodies[0].omega, -0.5);
  EXPECT_EQ(s.world.bodies[0].radius, 0.3);
  ASSERT_EQ(s.world.springs.size(), 2u);  // file order kept
  EXPECT_EQ(s.world.springs[0].body_i, 0);
  EXPECT_EQ(s.world.springs[0].body_j, kFixed);
  EXPECT_EQ(s.world.springs[0].anchor_i, Vec2(1.0, 2.0));
  EXPECT_EQ(s.world.springs[0].anchor_j, Vec2(3.0, 4.0));
  EXPECT_EQ(s.world.springs[0].stiffness, 5.0);
  EXPECT_EQ(s.world.springs[0].rest_length, 6.0);
  EXPECT_EQ(s.world.springs[1].body_i, kFixed);
  EXPECT_EQ(s.world.springs[1].body_j, 1);
  ASSERT_EQ(s.world.gravity.size(), 2u);
  EXPECT_EQ(s.world.gravity[0].acceleration, Vec2(0.5, -9.81));
  EXPECT_EQ(s.world.gravity[1].acceleration, Vec2(1.0, 0.0));
  ASSERT_EQ(s.world.winds.size(), 1u);
  EXPECT_EQ(s.world.winds[0].beta, 0.5);
  EXPECT_EQ(s.world.winds[0].velocity, Vec2(2.0, -1.0));
  EXPECT_EQ(s.world.winds[0].points_per_edge, 7);
  EXPECT_EQ(s.description, "hello world");
  EXPECT_EQ(s.tag, "RigidBody");
  ASSERT_TRUE(s.viewport.has_value());
  EXPECT_EQ(s.viewport->cy, 2.0);
  EXPECT_EQ(s.viewport->size, 3.0);
  ASSERT_TRUE(s.max_sim_freq.has_value());
  EXPECT_EQ(*s.max_sim_freq, 100.0);
  EXPECT_EQ(s.background.g, 0.5);
  EXPECT_EQ(s.background.b, 1.0);
  EXPECT_TRUE(s.warnings.empty());
}

TEST(ParseScene, ColoursAreAppliedAndDefaultsFillTheRest) {
  const Scene s = parse_ok(scene_with(
      "  <rigidbodycolor body=\"1\" r=\"0.0\" g=\"0.4\" b=\"1\"/>\n"  // before the body exists: fine
      "  <rigidbody p=\"0\" p=\"1\" p=\"2\" p=\"3\" vx=\"0\" vy=\"0\" omega=\"0\" r=\"0.1\"/>\n"
      "  <rigidbody p=\"0\" p=\"2\" vx=\"0\" vy=\"0\" omega=\"0\" r=\"0.1\"/>\n"
      "  <rigidbody p=\"1\" p=\"3\" vx=\"0\" vy=\"0\" omega=\"0\" r=\"0.1\"/>\n"
      "  <rigidbodyspringforce i=\"0\" pix=\"0\" piy=\"0\" j=\"1\" pjx=\"0\" pjy=\"0\" k=\"1\" l0=\"1\"/>\n"
      "  <rigidbodyspringforce i=\"1\" pix=\"0\" piy=\"0\" j=\"2\" pjx=\"0\" pjy=\"0\" k=\"1\" l0=\"1\"/>\n"
      "  <rigidbodyspringcolor spring=\"1\" r=\"0.2\" g=\"0\" b=\"0.8\"/>\n"
      "  <rigidbodycolor body=\"2\" r=\"1\" g=\"1\" b=\"1\"/>\n"
      "  <rigidbodycolor body=\"1\" r=\"0.5\" g=\"0.5\" b=\"0.5\"/>\n"));  // the last one wins
  ASSERT_EQ(s.body_colors.size(), 3u);
  EXPECT_EQ(s.body_colors[0].r, default_body_color(0).r);
  EXPECT_EQ(s.body_colors[0].g, default_body_color(0).g);
  EXPECT_EQ(s.body_colors[1].r, 0.5);
  EXPECT_EQ(s.body_colors[1].b, 0.5);
  EXPECT_EQ(s.body_colors[2].g, 1.0);
  ASSERT_EQ(s.spring_colors.size(), 2u);
  EXPECT_EQ(s.spring_colors[1].r, 0.2);
  EXPECT_EQ(s.spring_colors[1].b, 0.8);
  EXPECT_NE(s.spring_colors[0].b, 0.8);  // a default
}

TEST(ParseScene, DefaultBodyColoursAreValidAndDistinct) {
  for (std::int32_t i = 0; i < 10; ++i) {
    const Color c = default_body_color(i);
    for (double v : {c.r, c.g, c.b}) {
      EXPECT_GE(v, 0.0);
      EXPECT_LE(v, 1.0);
    }
    if (i > 0) {
      EXPECT_FALSE(c.r == default_body_color(i - 1).r && c.g == default_body_color(i - 1).g);
    }
  }
}

TEST(ParseScene, UnknownNodeAndAttributeAreWarningsNotErrors) {
  const std::string text = scene_with(
      "  <rigidbody p=\"0\" p=\"1\" p=\"2\" p=\"3\" vx=\"0\" vy=\"0\" omega=\"0\" r=\"0.1\"/>\n"
      "  <particle x=\"1\"/>\n"
      "  <rigidbodygravityforce fx=\"0\" fy=\"-1\" fz=\"3\"/>\n");
  const Scene s = parse_ok(text, "w.xml");
  ASSERT_EQ(s.warnings.size(), 2u);
  EXPECT_EQ(s.warnings[0], "w.xml:10: warning: unknown node <particle> ignored");
  EXPECT_EQ(s.warnings[1].rfind("w.xml:11: warning: ", 0), 0u) << s.warnings[1];
  EXPECT_NE(s.warnings[1].find("'fz'"), std::string::npos) << s.warnings[1];
  EXPECT_EQ(s.world.gravity.size(), 1u);
}

TEST(ParseScene, CommentsAndDeclarationsAreIgnored) {
  const Scene s = parse_ok(
      "<?xml version=\"1.0\"?>\n<!-- p=\"1\" p=\"2\" -->\n" +
      scene_with(
          "  <!-- a body -->\n  <rigidbody p=\"0\" p=\"1\" vx=\"0\" vy=\"0\" omega=\"0\" r=\"0.1\"/>\n"));
  EXPECT_EQ(s.world.bodies.size(), 1u);
  EXPECT_TRUE(s.warnings.empty());
}

TEST(ParseScene, LineNumbersSurviveMultiLineTagsWithRepeatedAttributes) {
  const std::string text = scene_with(
      "  <rigidbody p=\"0\"\n"
      "             p=\"1\"\n"
      "             p=\"2\" p=\"3\"\n"
      "             vx=\"0\" vy=\"0\" omega=\"0\" r=\"0.1\"/>\n"
      "  <rigidbodywindforce beta=\"1\" fx=\"1\" fy=\"0\" pointsperedge=\"1\"/>\n");
  Result<Scene> s = parse_scene(text, "lines.xml");
  ASSERT_FALSE(s);
  EXPECT_EQ(s.error().message,
            "lines.xml:13: <rigidbodywindforce> attribute 'pointsperedge': must be an integer in [2, "
            "1000000] (got 1)");
}

TEST(StepsFor, CeilingOfDurationOverDtInDoublePrecision) {
  EXPECT_EQ(steps_for(0.07, 0.01), 8);  // 0.07 / 0.01 = 7.000000000000001
  EXPECT_EQ(steps_for(4.0, 0.01), 400);
  EXPECT_EQ(steps_for(1.0, 0.001), 1000);
  EXPECT_EQ(steps_for(0.0, 0.01), 0);
  EXPECT_EQ(steps_for(0.015, 0.01), 2);
  constexpr auto kMax = std::numeric_limits<std::int64_t>::max();
  EXPECT_EQ(steps_for(4.9e101, 0.01), kMax);  // the fuzzer's: no int64 holds it
  EXPECT_EQ(steps_for(9.3e18, 1.0), kMax);
  EXPECT_EQ(steps_for(1.0, 0.0), kMax);  // +inf
  EXPECT_EQ(steps_for(std::nan(""), 0.01), 0);
  EXPECT_EQ(steps_for(9.0e15, 1.0), 9'000'000'000'000'000);
  Scene s;
  s.duration = 0.07;
  s.world.dt = 0.01;
  EXPECT_EQ(s.step_count(), 8);
}

TEST(ParseScene, ZeroDurationIsValid) {
  std::string text = scene_with("  <rigidbody p=\"0\" p=\"1\" vx=\"0\" vy=\"0\" omega=\"0\" r=\"0.1\"/>\n");
  text.replace(text.find("time=\"1.0\""), 10, "time=\"0\"");
  const Scene s = parse_ok(text);
  EXPECT_EQ(s.duration, 0.0);
  EXPECT_EQ(s.step_count(), 0);
}

}  // namespace
}  // namespace rbsim
