// Spring force and torque: consistency with the potential, and the zero-length cases.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "rbsim/builders.hpp"
#include "test_util.hpp"

namespace rbsim {
namespace {

using test::make_world;

// Force and torque the world accumulates for the given states (read back after one step, which
// evaluates forces at the start of the step).
struct Generalised {
  std::vector<Vec2> force;
  std::vector<double> torque;
};
Generalised forces_at(const WorldDef& def, const std::vector<BodyState>& states) {
  World w = make_world(def);
  for (std::size_t b = 0; b < states.size(); ++b)
    w.set_state(BodyId{static_cast<std::int32_t>(b)}, states[b]);
  w.step();
  Generalised g;
  for (std::int32_t b = 0; b < w.body_count(); ++b) {
    g.force.push_back(w.force(BodyId{b}));
    g.torque.push_back(w.torque(BodyId{b}));
  }
  return g;
}

double potential_at(const WorldDef& def, const std::vector<BodyState>& states) {
  World w = make_world(def);
  for (std::size_t b = 0; b < states.size(); ++b)
    w.set_state(BodyId{static_cast<std::int32_t>(b)}, states[b]);
  return w.energy().u_spring;
}

// force = -dU/dX, torque = -dU/dtheta, by central differences, for random states and anchors
// (springs between two bodies, to fixed points on either end, and with l0 = 0).
TEST(WorldStep, SpringForceAndTorqueAreMinusGradientOfPotential) {
  std::mt19937_64 rng(12345);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  int checked = 0;
  for (int trial = 0; trial < 60; ++trial) {
    WorldDef def;
    def.dt = 1e-3;
    def.bodies.push_back(builders::polygon(3 + trial % 4, 1.0 + 0.1 * (trial % 3), {u(rng), u(rng)}));
    def.bodies.push_back(builders::square({3.0 + u(rng), u(rng)}));
    def.bodies[1].masses = {1.0, 0.5, 2.0, 1.5};
    SpringDef s;
    s.body_i = trial % 3 == 2 ? kFixed : 0;
    s.anchor_i = {u(rng), u(rng)};
    s.body_j = trial % 3 == 1 ? kFixed : 1;
    s.anchor_j = {u(rng), u(rng)};
    s.stiffness = 0.5 + std::abs(u(rng)) * 5.0;
    s.rest_length = trial % 5 == 0 ? 0.0 : std::abs(u(rng)) * 2.0;
    def.springs.push_back(s);

    std::vector<BodyState> states(2);
    for (BodyState& st : states) st = BodyState{{u(rng), u(rng)}, u(rng) * 3.0, {0.0, 0.0}, 0.0};
    states[1].position.x() += 4.0;
    {
      World check = make_world(def);
      for (std::size_t b = 0; b < 2; ++b) check.set_state(BodyId{static_cast<std::int32_t>(b)}, states[b]);
      if (check.spring_state(SpringId{0}).length < 0.05) continue;  // keep away from the l = 0 kink
    }
    const Generalised g = forces_at(def, states);
    const double eps = 1e-6;
    for (std::size_t b = 0; b < 2; ++b) {
      auto derivative = [&](auto perturb) {
        std::vector<BodyState> plus = states, minus = states;
        perturb(plus[b], eps);
        perturb(minus[b], -eps);
        return (potential_at(def, plus) - potential_at(def, minus)) / (2.0 * eps);
      };
      const double dudx = derivative([](BodyState& st, double e) { st.position.x() += e; });
      const double dudy = derivative([](BodyState& st, double e) { st.position.y() += e; });
      const double dudt = derivative([](BodyState& st, double e) { st.theta += e; });
      const double scale = 1.0 + g.force[b].norm() + std::abs(g.torque[b]);
      EXPECT_NEAR(g.force[b].x(), -dudx, 1e-6 * scale) << "trial " << trial << " body " << b;
      EXPECT_NEAR(g.force[b].y(), -dudy, 1e-6 * scale) << "trial " << trial << " body " << b;
      EXPECT_NEAR(g.torque[b], -dudt, 1e-6 * scale) << "trial " << trial << " body " << b;
    }
    ++checked;
  }
  EXPECT_GT(checked, 50);
}

// The torque about the centre of mass equals the lever arm crossed with the force.
TEST(WorldStep, SpringTorqueIsLeverArmCrossForce) {
  WorldDef def;
  def.dt = 0.01;
  def.bodies.push_back(builders::square({0.0, 0.0}));
  def.springs.push_back(test::spring(0, {1.0, 1.0}, kFixed, {4.0, 1.0}, 2.0, 1.0));
  World w = make_world(def);
  w.step();
  // end at (1, 1), fixed at (4, 1): l = 3, pulled +x with k (l - l0) = 4; arm (1, 1) x (4, 0) = -4
  EXPECT_DOUBLE_EQ(w.force(BodyId{0}).x(), 4.0);
  EXPECT_DOUBLE_EQ(w.force(BodyId{0}).y(), 0.0);
  EXPECT_DOUBLE_EQ(w.torque(BodyId{0}), -4.0);
  // compressed spring pushes the other way
  def.springs[0].rest_length = 5.0;
  World c = make_world(def);
  c.step();
  EXPECT_DOUBLE_EQ(c.force(BodyId{0}).x(), -4.0);
  EXPECT_DOUBLE_EQ(c.torque(BodyId{0}), 4.0);
}

TEST(WorldSpringState, EndpointsLengthAndPotential) {
  WorldDef def;
  def.bodies.push_back(builders::square({1.0, 2.0}));
  def.springs.push_back(test::spring(0, {1.0, 0.0}, kFixed, {5.0, 5.0}, 2.0, 1.0));
  World w = make_world(def);
  BodyState s = w.state(BodyId{0});
  s.theta = std::acos(0.0);  // anchor (1, 0) rotates to (0, 1)
  w.set_state(BodyId{0}, s);
  const SpringState st = w.spring_state(SpringId{0});
  EXPECT_NEAR(st.end_i.x(), 1.0, 1e-15);
  EXPECT_NEAR(st.end_i.y(), 3.0, 1e-15);
  EXPECT_EQ(st.end_j, Vec2(5.0, 5.0));
  EXPECT_NEAR(st.length, std::sqrt(16.0 + 4.0), 1e-14);
  EXPECT_NEAR(st.potential, 0.5 * 2.0 * std::pow(std::sqrt(20.0) - 1.0, 2), 1e-13);
  EXPECT_NEAR(w.energy().u_spring, st.potential, 0.0);
}

// ---------------------------------------------------------------------------------------------
// Zero-length springs (docs/rigid-body-milestone.md 4.7 note; spring_force_on_i in step.cpp):
//   l0 = 0:           F = k (rj - ri), zero when the ends meet, never 0/0;
//   l0 > 0 and l = 0: no force (direction undefined), potential k l0^2 / 2 still counted.
WorldDef body_on_zero_spring(double l0, Vec2 body_at, Vec2 fixed_at, Vec2 anchor = {0.0, 0.0}) {
  WorldDef def;
  def.dt = 0.01;
  def.bodies.push_back(builders::square(body_at));
  def.springs.push_back(test::spring(kFixed, fixed_at, 0, anchor, 3.0, l0));
  return def;
}

TEST(WorldStep, ZeroRestLengthWithCoincidentEndsGivesNoForceAndNoNaN) {
  World w = make_world(body_on_zero_spring(0.0, {2.0, -1.0}, {2.0, -1.0}));
  for (int i = 0; i < 10; ++i) w.step();
  EXPECT_FALSE(w.find_nonfinite().has_value());
  EXPECT_EQ(w.force(BodyId{0}), Vec2(0.0, 0.0));
  EXPECT_EQ(w.torque(BodyId{0}), 0.0);
  EXPECT_EQ(w.state(BodyId{0}).position, Vec2(2.0, -1.0));
  EXPECT_EQ(w.spring_state(SpringId{0}).potential, 0.0);
  EXPECT_EQ(w.spring_state(SpringId{0}).length, 0.0);
}

TEST(WorldStep, ZeroRestLengthSpringIsLinearInSeparation) {
  // fixed end at the origin, body end at (3, 4): F = k (rj - ri) on end i, so -k (3, 4) on the body
  World w = make_world(body_on_zero_spring(0.0, {3.0, 4.0}, {0.0, 0.0}));
  w.step();
  EXPECT_DOUBLE_EQ(w.force(BodyId{0}).x(), -9.0);
  EXPECT_DOUBLE_EQ(w.force(BodyId{0}).y(), -12.0);
  // and an off-centre anchor that coincides with the fixed point: no force, no torque
  World a = make_world(body_on_zero_spring(0.0, {0.0, 0.0}, {1.0, 1.0}, {1.0, 1.0}));
  a.step();
  EXPECT_EQ(a.force(BodyId{0}), Vec2(0.0, 0.0));
  EXPECT_EQ(a.torque(BodyId{0}), 0.0);
  EXPECT_FALSE(a.find_nonfinite().has_value());
}

TEST(WorldStep, PositiveRestLengthWithCoincidentEndsGivesNoForceButKeepsPotential) {
  World w = make_world(body_on_zero_spring(1.5, {0.0, 0.0}, {1.0, -1.0}, {1.0, -1.0}));
  const double u0 = w.energy().u_spring;
  EXPECT_DOUBLE_EQ(u0, 0.5 * 3.0 * 1.5 * 1.5);
  for (int i = 0; i < 10; ++i) w.step();
  EXPECT_FALSE(w.find_nonfinite().has_value());
  EXPECT_EQ(w.force(BodyId{0}), Vec2(0.0, 0.0));
  EXPECT_EQ(w.torque(BodyId{0}), 0.0);
  EXPECT_EQ(w.state(BodyId{0}).position, Vec2(0.0, 0.0));
  EXPECT_EQ(w.state(BodyId{0}).theta, 0.0);
  EXPECT_DOUBLE_EQ(w.energy().u_spring, u0);
  EXPECT_TRUE(std::isfinite(w.energy().total()));
}

TEST(WorldStep, ZeroStiffnessSpringDoesNothing) {
  WorldDef def = body_on_zero_spring(2.0, {3.0, 4.0}, {0.0, 0.0}, {0.5, 0.5});
  def.springs[0].stiffness = 0.0;
  World w = make_world(def);
  w.step();
  EXPECT_EQ(w.force(BodyId{0}).norm(), 0.0);
  EXPECT_EQ(w.torque(BodyId{0}), 0.0);
  EXPECT_EQ(w.energy().u_spring, 0.0);
}

}  // namespace
}  // namespace rbsim
