// Momentum and angular momentum: exact where the arithmetic allows it, to rounding elsewhere.
#include <gtest/gtest.h>

#include <cmath>

#include "rbsim/builders.hpp"
#include "test_util.hpp"

namespace rbsim {
namespace {

using test::make_world;
using test::same_bits;

class WorldStepNoForces : public ::testing::TestWithParam<Integrator> {};

// No forces: V and omega are never touched (v += h * 0 / m), so P, L_spin, T_point and T_spin
// are bit-identical at every step. L_point = M (X x V) is conserved by the continuum motion
// X = X0 + t V, but X accumulates one rounding per step, so L is conserved to ~n eps.
TEST_P(WorldStepNoForces, MomentumExactAngularMomentumToRounding) {
  World w = make_world(builders::free_bodies(GetParam(), 0.01, 7));
  const auto n = w.body_count();
  std::vector<BodyQuantities> q0;
  for (std::int32_t b = 0; b < n; ++b) q0.push_back(w.quantities(BodyId{b}));
  const test::Totals t0 = test::totals(w);
  double worst_rel = 0.0;
  for (int step = 1; step <= 2000; ++step) {
    w.step();
    for (std::int32_t b = 0; b < n; ++b) {
      const BodyQuantities q = w.quantities(BodyId{b});
      ASSERT_TRUE(same_bits(q.momentum.x(), q0[b].momentum.x())) << "step " << step << " body " << b;
      ASSERT_TRUE(same_bits(q.momentum.y(), q0[b].momentum.y())) << "step " << step << " body " << b;
      ASSERT_TRUE(same_bits(q.l_spin, q0[b].l_spin));
      ASSERT_TRUE(same_bits(q.t_point, q0[b].t_point));
      ASSERT_TRUE(same_bits(q.t_spin, q0[b].t_spin));
      EXPECT_EQ(w.force(BodyId{b}), Vec2(0.0, 0.0));
      EXPECT_EQ(w.torque(BodyId{b}), 0.0);
    }
    const test::Totals t = test::totals(w);
    worst_rel = std::max(worst_rel, std::abs(t.l - t0.l) / t.l_scale);
  }
  EXPECT_LT(worst_rel, 1e-12);
  // and the motion really happened: positions and angles moved as X0 + t V, theta0 + t omega
  const WorldDef def = builders::free_bodies(GetParam(), 0.01, 7);
  for (std::int32_t b = 0; b < n; ++b) {
    const BodyState s = w.state(BodyId{b});
    EXPECT_NEAR(s.theta, 20.0 * def.bodies[b].omega, 1e-11);
  }
}

INSTANTIATE_TEST_SUITE_P(BothIntegrators, WorldStepNoForces,
                         ::testing::Values(Integrator::ExplicitEuler, Integrator::SymplecticEuler),
                         [](const auto& tp) {
                           return tp.param == Integrator::ExplicitEuler ? "Explicit" : "Symplectic";
                         });

// Two bodies joined by springs at off-centre anchors (internal forces only, with torques).
WorldDef spring_pair(Integrator integrator, double dt) {
  WorldDef def;
  def.integrator = integrator;
  def.dt = dt;
  def.bodies.push_back(builders::polygon(5, 1.0, {-2.0, 0.5}, {0.3, -0.2}, 0.8));
  BodyDef b = builders::square({2.5, -1.0}, {-0.1, 0.4}, -0.5);
  b.masses = {1.0, 2.0, 0.5, 1.5};
  def.bodies.push_back(b);
  SpringDef s;
  s.body_i = 0;
  s.anchor_i = {0.7, 0.2};
  s.body_j = 1;
  s.anchor_j = {-0.9, 0.6};
  s.stiffness = 5.0;
  s.rest_length = 2.0;
  def.springs.push_back(s);
  s.anchor_i = {-0.3, -0.8};
  s.anchor_j = {0.4, -0.4};
  s.stiffness = 3.0;
  s.rest_length = 4.5;
  def.springs.push_back(s);
  return def;
}

// Symplectic Euler (velocities first) conserves total angular momentum exactly in exact
// arithmetic for forces from a rotation-invariant potential:
//   L' = sum (X + h V') x M V' + I omega' = L + h (sum X x F + tau) = L.
// Explicit Euler gains h^2 sum V x F per step instead. Both conserve P (action = reaction).
TEST(WorldStep, InternalSpringsConserveMomentumAndSymplecticConservesAngularMomentum) {
  const double dt = 0.01;
  World sym = make_world(spring_pair(Integrator::SymplecticEuler, dt));
  World exp = make_world(spring_pair(Integrator::ExplicitEuler, dt));
  const test::Totals s0 = test::totals(sym), e0 = test::totals(exp);
  double sym_l = 0.0, exp_l = 0.0, sym_p = 0.0, exp_p = 0.0, spin_change = 0.0;
  for (int step = 0; step < 5000; ++step) {
    sym.step();
    exp.step();
    const test::Totals s = test::totals(sym), e = test::totals(exp);
    sym_l = std::max(sym_l, std::abs(s.l - s0.l) / s.l_scale);
    exp_l = std::max(exp_l, std::abs(e.l - e0.l) / e.l_scale);
    sym_p = std::max(sym_p, (s.p - s0.p).norm());
    exp_p = std::max(exp_p, (e.p - e0.p).norm());
    spin_change = std::max(spin_change, std::abs(s.l_spin - s0.l_spin));
  }
  EXPECT_LT(sym_l, 1e-12);
  EXPECT_LT(sym_p, 1e-12);
  EXPECT_LT(exp_p, 1e-12);
  // Explicit Euler's drift is real and of order h (summed h^2 over 1/h steps per unit time)...
  EXPECT_GT(exp_l, 1e-4);
  // ...and the springs really exchange angular momentum between spin and orbit.
  EXPECT_GT(spin_change, 0.1);
}

// A spring with both ends on the same body is internal to a rigid body: no net force or torque.
TEST(WorldStep, SpringWithBothEndsOnOneBodyExertsNothing) {
  WorldDef def;
  def.dt = 0.01;
  def.bodies.push_back(builders::square({0.0, 0.0}, {0.0, 0.0}, 0.3));
  def.springs.push_back(test::spring(0, {1.0, 0.0}, 0, {-1.0, 0.5}, 10.0, 0.5));
  World w = make_world(def);
  w.step();
  EXPECT_NEAR(w.force(BodyId{0}).norm(), 0.0, 1e-14);
  EXPECT_NEAR(w.torque(BodyId{0}), 0.0, 1e-14);
  EXPECT_EQ(w.state(BodyId{0}).omega, 0.3);
}

// Gravity acts at the centre of mass: no torque even on an asymmetric body.
TEST(WorldStep, GravityExertsNoTorqueOnAsymmetricBody) {
  WorldDef def;
  def.dt = 0.01;
  BodyDef b;
  b.hull = {{0.0, 0.0}, {0.0, 6.0}, {4.0, 0.0}};
  b.masses = {1.0, 3.0, 2.0};
  b.omega = 0.25;
  def.bodies.push_back(b);
  def.gravity.push_back(GravityDef{{0.5, -9.81}});
  def.gravity.push_back(GravityDef{{-1.5, 0.0}});  // several gravity forces add up
  World w = make_world(def);
  for (int i = 0; i < 100; ++i) w.step();
  EXPECT_EQ(w.torque(BodyId{0}), 0.0);
  EXPECT_EQ(w.state(BodyId{0}).omega, 0.25);
  EXPECT_NEAR(w.force(BodyId{0}).x(), 6.0 * -1.0, 1e-14);
  EXPECT_NEAR(w.force(BodyId{0}).y(), 6.0 * -9.81, 1e-13);
}

}  // namespace
}  // namespace rbsim
