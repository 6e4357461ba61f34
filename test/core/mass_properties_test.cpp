// Total mass, centre of mass and moment of inertia of known shapes
// (docs/rigid-body-milestone.md 3.1, 3.3.2, 4.1).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "rbsim/builders.hpp"
#include "test_util.hpp"

namespace rbsim {
namespace {

using test::make_world;

WorldDef one_body(const BodyDef& body) {
  WorldDef def;
  def.bodies.push_back(body);
  return def;
}

TEST(WorldCreate, SquareHasMassFourInertiaEightAndCentreAtItsMiddle) {
  const World w = make_world(one_body(builders::square({3.0, -2.0})));
  EXPECT_EQ(w.mass(BodyId{0}), 4.0);
  EXPECT_EQ(w.inertia(BodyId{0}), 8.0);
  const BodyState s = w.state(BodyId{0});
  EXPECT_EQ(s.position, Vec2(3.0, -2.0));
  EXPECT_EQ(s.theta, 0.0);
}

TEST(WorldCreate, AsymmetricMassDistribution) {
  // masses 1, 2, 3 at (0,0), (4,0), (0,6):  M = 6,  X = (8/6, 18/6) = (4/3, 3),
  // I = sum m |r|^2 - M |X|^2 = (2*16 + 3*36) - 6 (16/9 + 9) = 140 - 194/3 = 226/3.
  BodyDef b;
  b.hull = {{0.0, 0.0}, {0.0, 6.0}, {4.0, 0.0}};
  b.masses = {1.0, 3.0, 2.0};
  const World w = make_world(one_body(b));
  EXPECT_DOUBLE_EQ(w.mass(BodyId{0}), 6.0);
  EXPECT_NEAR(w.state(BodyId{0}).position.x(), 4.0 / 3.0, 1e-15);
  EXPECT_NEAR(w.state(BodyId{0}).position.y(), 3.0, 1e-15);
  EXPECT_NEAR(w.inertia(BodyId{0}), 226.0 / 3.0, 1e-12);
  // Not the unweighted centroid (4/3, 2): a weights-ignored bug would show here.
  EXPECT_GT(std::abs(w.state(BodyId{0}).position.y() - 2.0), 0.5);
}

TEST(WorldCreate, BodySpaceHullIsRelativeToCentreOfMassAndBalanced) {
  BodyDef b;
  b.hull = {{1.0, 1.0}, {2.0, 5.0}, {6.0, 3.0}, {5.0, -1.0}};
  b.masses = {0.5, 2.0, 1.25, 3.0};
  const World w = make_world(one_body(b));
  const auto hull = w.hull(BodyId{0});
  ASSERT_EQ(hull.size(), 4u);
  Vec2 moment(0.0, 0.0);
  double inertia = 0.0;
  for (std::size_t i = 0; i < hull.size(); ++i) {
    EXPECT_NEAR((hull[i] + w.state(BodyId{0}).position - b.hull[i]).norm(), 0.0, 1e-14) << "vertex " << i;
    moment += b.masses[i] * hull[i];
    inertia += b.masses[i] * hull[i].squaredNorm();
    // world_vertex at theta = 0 gives back the scene's vertices
    EXPECT_NEAR((w.world_vertex(BodyId{0}, static_cast<std::int32_t>(i)) - b.hull[i]).norm(), 0.0, 1e-14);
  }
  EXPECT_NEAR(moment.norm(), 0.0, 1e-13);
  EXPECT_NEAR(w.inertia(BodyId{0}), inertia, 1e-12);
  EXPECT_DOUBLE_EQ(w.mass(BodyId{0}), 6.75);
}

TEST(WorldCreate, TwoVertexRod) {
  BodyDef b;
  b.hull = {{-1.0, 0.0}, {3.0, 0.0}};
  b.masses = {3.0, 1.0};  // X = (0, 0); I = 3*1 + 1*9 = 12
  const World w = make_world(one_body(b));
  EXPECT_EQ(w.mass(BodyId{0}), 4.0);
  EXPECT_EQ(w.state(BodyId{0}).position, Vec2(0.0, 0.0));
  EXPECT_EQ(w.inertia(BodyId{0}), 12.0);
}

TEST(WorldCreate, InertiaScalesWithMassAndSquareOfSize) {
  for (int n : {3, 5, 8}) {
    BodyDef small = builders::polygon(n, 1.0, {0.0, 0.0});
    BodyDef big = builders::polygon(n, 3.0, {7.0, 7.0});
    for (double& m : big.masses) m = 2.0;
    const World a = make_world(one_body(small));
    const World b = make_world(one_body(big));
    // a regular n-gon of unit masses at radius r: I = n r^2
    EXPECT_NEAR(a.inertia(BodyId{0}), n * 1.0, 1e-12) << n;
    EXPECT_NEAR(b.inertia(BodyId{0}), 2.0 * 9.0 * n, 1e-11) << n;
    EXPECT_NEAR((b.state(BodyId{0}).position - Vec2(7.0, 7.0)).norm(), 0.0, 1e-14);
  }
}

TEST(WorldVertex, FollowsRotationCounterClockwise) {
  World w = make_world(one_body(builders::square({1.0, 2.0})));
  BodyState s = w.state(BodyId{0});
  s.theta = std::numbers::pi / 2;
  w.set_state(BodyId{0}, s);
  // body-space vertex 0 is (-1, -1); rotated CCW by 90 degrees it is (1, -1)
  const Vec2 v = w.world_vertex(BodyId{0}, 0);
  EXPECT_NEAR(v.x(), 1.0 + 1.0, 1e-15);
  EXPECT_NEAR(v.y(), 2.0 - 1.0, 1e-15);
}

TEST(WorldQuantities, MatchTheirDefinitions) {
  BodyDef b = builders::square({2.0, -3.0}, {0.5, 1.5}, -0.75);
  const World w = make_world(one_body(b));
  const BodyQuantities q = w.quantities(BodyId{0});
  EXPECT_EQ(q.momentum, Vec2(2.0, 6.0));                   // M V
  EXPECT_EQ(q.l_point, 4.0 * (2.0 * 1.5 - (-3.0) * 0.5));  // M X x V = 18
  EXPECT_EQ(q.l_spin, 8.0 * -0.75);                        // I omega
  EXPECT_EQ(q.t_point, 0.5 * 4.0 * (0.25 + 2.25));         // M |V|^2 / 2
  EXPECT_EQ(q.t_spin, 0.5 * 8.0 * 0.75 * 0.75);            // I omega^2 / 2
}

TEST(WorldQuantities, SpinEnergyEqualsSumOfVertexKineticEnergies) {
  // T_point + T_spin is the kinetic energy of the point masses: sum m_i |V + omega J r'_i|^2 / 2.
  BodyDef b;
  b.hull = {{0.0, 0.0}, {1.0, 4.0}, {5.0, 1.0}};
  b.masses = {1.0, 2.5, 0.5};
  b.velocity = {0.3, -1.2};
  b.omega = 2.0;
  const World w = make_world(one_body(b));
  const BodyQuantities q = w.quantities(BodyId{0});
  double t = 0.0, l = 0.0;
  const Vec2 x = w.state(BodyId{0}).position;
  for (std::size_t i = 0; i < b.hull.size(); ++i) {
    const Vec2 r = b.hull[i] - x;
    const Vec2 v = b.velocity + b.omega * test::perp(r);
    t += 0.5 * b.masses[i] * v.squaredNorm();
    l += b.masses[i] * test::cross(b.hull[i], v);  // about the origin
  }
  EXPECT_NEAR(q.t_point + q.t_spin, t, 1e-12 * t);
  EXPECT_NEAR(q.l_point + q.l_spin, l, 1e-12 * std::abs(l));
}

TEST(WorldEnergy, GravityPotentialIsMinusMassTimesGDotX) {
  WorldDef def = builders::free_fall(Integrator::SymplecticEuler, 0.01, {1.0, -9.81}, {0.0, 0.0});
  const World w = make_world(def);
  const Energy e = w.energy();
  // square at (0, 10), M = 4: U = -4 (1*0 + -9.81*10) = 392.4
  EXPECT_DOUBLE_EQ(e.u_gravity, 392.4);
  EXPECT_EQ(e.u_spring, 0.0);
  EXPECT_EQ(e.kinetic(), 0.0);
  EXPECT_EQ(w.potential_energy(), e.u_gravity);
  EXPECT_EQ(e.total(), e.potential() + e.kinetic());
}

TEST(WorldCreate, BitIdenticalHullsShareOneShape) {
  WorldDef def;
  def.bodies.push_back(builders::square({0.0, 0.0}));
  def.bodies.push_back(builders::square({10.0, 0.0}));
  def.bodies.push_back(builders::polygon(5, 1.0, {0.0, 0.0}));
  const World w = make_world(def);
  EXPECT_EQ(w.shape_count(), 2);
  EXPECT_EQ(w.hull(BodyId{0}).data(), w.hull(BodyId{1}).data());
  EXPECT_EQ(w.inertia(BodyId{1}), 8.0);
  EXPECT_EQ(w.state(BodyId{1}).position, Vec2(10.0, 0.0));
}

// polygon_contains: a hull's inside by winding number, in either vertex order, a concave notch
// outside, and a 2-vertex hull (a rod) enclosing nothing.
TEST(PolygonContains, InsideByWindingInEitherOrder) {
  const std::vector<Vec2> square{{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
  const std::vector<Vec2> clockwise(square.rbegin(), square.rend());
  for (const auto& hull : {square, clockwise}) {
    EXPECT_TRUE(polygon_contains(hull, Vec2(0.0, 0.0)));
    EXPECT_TRUE(polygon_contains(hull, Vec2(0.99, -0.99)));
    EXPECT_FALSE(polygon_contains(hull, Vec2(1.01, 0.0)));
    EXPECT_FALSE(polygon_contains(hull, Vec2(0.0, -1.5)));
  }
  // A U shape: the notch between its arms is outside.
  const std::vector<Vec2> u{{0, 0}, {3, 0}, {3, 3}, {2, 3}, {2, 1}, {1, 1}, {1, 3}, {0, 3}};
  EXPECT_TRUE(polygon_contains(u, Vec2(0.5, 2.5)));
  EXPECT_FALSE(polygon_contains(u, Vec2(1.5, 2.0)));
  EXPECT_FALSE(polygon_contains(std::vector<Vec2>{{0, 0}, {2, 0}}, Vec2(1.0, 0.0)));
  EXPECT_FALSE(polygon_contains(std::vector<Vec2>{}, Vec2(0.0, 0.0)));
}

}  // namespace
}  // namespace rbsim
