// Changes to a world between steps (World::set_gravity, set_wind, set_spring, apply_impulse): the
// impulse against its analytic result, and every setter against a world made with the changed
// definition, bit for bit.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "rbsim/builders.hpp"
#include "test_util.hpp"

namespace rbsim {
namespace {

using test::cross;
using test::make_world;
using test::rotate;
using test::same_bits;

// Every state value of two worlds, bit for bit.
void expect_same_state(const World& a, const World& b) {
  ASSERT_EQ(a.body_count(), b.body_count());
  EXPECT_EQ(a.step_index(), b.step_index());
  for (auto [sa, sb] : {std::pair{a.x(), b.x()},
                        {a.y(), b.y()},
                        {a.theta(), b.theta()},
                        {a.vx(), b.vx()},
                        {a.vy(), b.vy()},
                        {a.omega(), b.omega()}}) {
    for (std::size_t i = 0; i < sa.size(); ++i) {
      ASSERT_TRUE(same_bits(sa[i], sb[i])) << "body " << i << ": " << sa[i] << " vs " << sb[i];
    }
  }
}

void step(World& w, int n) {
  for (int k = 0; k < n; ++k) w.step();
}

// A spinning, moving square: theta is far from 0 when the impulse lands.
World spinning_square() {
  WorldDef def;
  def.bodies.push_back(builders::polygon(5, 1.5, {2.0, -1.0}, {0.3, -0.2}, 1.7));
  def.gravity.push_back(GravityDef{{0.0, -9.81}});
  World w = make_world(def);
  step(w, 37);
  return w;
}

TEST(WorldApplyImpulse, ChangesMomentumByJAndSpinByLeverArmCrossJ) {
  World w = spinning_square();
  const BodyId b{0};
  const BodyState before = w.state(b);
  const BodyQuantities q0 = w.quantities(b);
  const Vec2 j(2.5, -4.0), p(0.4, 1.1);
  ASSERT_TRUE(w.apply_impulse(b, j, p).ok());
  const BodyState after = w.state(b);
  const BodyQuantities q1 = w.quantities(b);
  // Positions do not move: an impulse acts over no time.
  EXPECT_TRUE(same_bits(after.position.x(), before.position.x()));
  EXPECT_TRUE(same_bits(after.position.y(), before.position.y()));
  EXPECT_TRUE(same_bits(after.theta, before.theta));
  // dP = J (to rounding of M (V + J / M) - M V).
  const double tol = 1e-13 * (j.norm() + q0.momentum.norm());
  EXPECT_NEAR(q1.momentum.x() - q0.momentum.x(), j.x(), tol);
  EXPECT_NEAR(q1.momentum.y() - q0.momentum.y(), j.y(), tol);
  // dL_spin = (R(theta) p) x J; dL about the origin = (X + R p) x J.
  const Vec2 arm = rotate(before.theta, p);
  const double spin = cross(arm, j);
  const double ltol = 1e-12 * (std::abs(spin) + std::abs(q0.l_spin) + std::abs(q0.l_point) + 1.0);
  EXPECT_NEAR(q1.l_spin - q0.l_spin, spin, ltol);
  EXPECT_NEAR((q1.l_point + q1.l_spin) - (q0.l_point + q0.l_spin), cross(before.position + arm, j), ltol);
}

TEST(WorldApplyImpulse, AtTheCentreOfMassLeavesTheSpin) {
  World w = spinning_square();
  const double omega = w.state(BodyId{0}).omega;
  ASSERT_TRUE(w.apply_impulse(BodyId{0}, {1.0, 2.0}, {0.0, 0.0}).ok());
  EXPECT_TRUE(same_bits(w.state(BodyId{0}).omega, omega));
}

TEST(WorldApplyImpulse, RefusesBadArgumentsAndChangesNothing) {
  World w = spinning_square();
  const World untouched = w;
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(w.apply_impulse(BodyId{1}, {1.0, 0.0}, {0.0, 0.0}).ok());
  EXPECT_FALSE(w.apply_impulse(BodyId{-1}, {1.0, 0.0}, {0.0, 0.0}).ok());
  EXPECT_FALSE(w.apply_impulse(BodyId{0}, {nan, 0.0}, {0.0, 0.0}).ok());
  EXPECT_FALSE(w.apply_impulse(BodyId{0}, {0.0, 1.0}, {inf, 0.0}).ok());
  expect_same_state(w, untouched);
}

// A world changed at step 0 steps exactly as one made with the changed definition.
TEST(WorldSetGravity, AtStepZeroEqualsAWorldMadeWithThatGravity) {
  WorldDef def = builders::grid(12, true);
  World changed = make_world(def);
  ASSERT_TRUE(changed.set_gravity(0, {0.5, -3.7}).ok());
  def.gravity[0].acceleration = {0.5, -3.7};
  World made = make_world(def);
  EXPECT_TRUE(same_bits(changed.finite_bound(), made.finite_bound()));
  step(changed, 200);
  step(made, 200);
  expect_same_state(changed, made);
}

// Mid-run: the changed world against a world made with the new definition and given the state at
// the change.
TEST(WorldSetGravity, MidRunEqualsARestartWithThatGravity) {
  WorldDef def = builders::grid(6, true);
  World changed = make_world(def);
  step(changed, 50);
  ASSERT_TRUE(changed.set_gravity(0, {-1.0, 2.0}).ok());
  def.gravity[0].acceleration = {-1.0, 2.0};
  World made = make_world(def);
  for (std::int32_t b = 0; b < made.body_count(); ++b) made.set_state(BodyId{b}, changed.state(BodyId{b}));
  made.set_step_index(changed.step_index());
  step(changed, 100);
  step(made, 100);
  expect_same_state(changed, made);
}

TEST(WorldSetWind, AtStepZeroEqualsAWorldMadeWithThatWind) {
  WorldDef def = builders::grid(12, true);
  ASSERT_EQ(def.winds.size(), 1u);
  World changed = make_world(def);
  WindDef wind = def.winds[0];
  wind.beta = 0.37;
  wind.velocity = {-2.0, 0.75};
  wind.points_per_edge = wind.points_per_edge + 5;  // the moments must be recomputed
  ASSERT_TRUE(changed.set_wind(0, wind).ok());
  def.winds[0] = wind;
  World made = make_world(def);
  step(changed, 200);
  step(made, 200);
  expect_same_state(changed, made);
}

TEST(WorldSetWind, PointsPerEdgeChangesTheMotion) {
  // The test above would pass if points per edge were ignored by both; this one would not.
  WorldDef def = builders::square_in_wind(Integrator::SymplecticEuler, 0.01, {1.0, 0.5}, 1.0, 2);
  def.bodies[0].omega = 2.0;
  World two = make_world(def), seven = make_world(def);
  WindDef wind = def.winds[0];
  wind.points_per_edge = 7;
  ASSERT_TRUE(seven.set_wind(0, wind).ok());
  step(two, 50);
  step(seven, 50);
  EXPECT_NE(two.state(BodyId{0}).omega, seven.state(BodyId{0}).omega);
}

TEST(WorldSetSpring, AtStepZeroEqualsAWorldMadeWithThatSpring) {
  WorldDef def = builders::grid(12, true);
  World changed = make_world(def);
  ASSERT_TRUE(changed.set_spring(SpringId{3}, 17.5, 0.25).ok());
  def.springs[3].stiffness = 17.5;
  def.springs[3].rest_length = 0.25;
  World made = make_world(def);
  EXPECT_TRUE(same_bits(changed.finite_bound(), made.finite_bound()));
  step(changed, 200);
  step(made, 200);
  expect_same_state(changed, made);
}

TEST(WorldSetters, RefuseWhatTheSceneLoaderRefusesAndChangeNothing) {
  const WorldDef def = builders::grid(4, true);
  World w = make_world(def);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(w.set_gravity(1, {0.0, 1.0}).ok());
  EXPECT_FALSE(w.set_gravity(-1, {0.0, 1.0}).ok());
  EXPECT_FALSE(w.set_gravity(0, {nan, 1.0}).ok());
  WindDef wind = def.winds[0];
  wind.beta = -1.0;
  EXPECT_FALSE(w.set_wind(0, wind).ok());
  wind = def.winds[0];
  wind.points_per_edge = 0;
  EXPECT_FALSE(w.set_wind(0, wind).ok());
  EXPECT_FALSE(w.set_wind(1, def.winds[0]).ok());
  EXPECT_FALSE(w.set_spring(SpringId{4}, 1.0, 1.0).ok());
  EXPECT_FALSE(w.set_spring(SpringId{0}, -1.0, 1.0).ok());
  EXPECT_FALSE(w.set_spring(SpringId{0}, 1.0, nan).ok());
  World fresh = make_world(def);
  step(w, 100);
  step(fresh, 100);
  expect_same_state(w, fresh);
}

}  // namespace
}  // namespace rbsim
