// Explicit and symplectic Euler against closed forms: free fall, the harmonic spring, energy
// behaviour, the update order, determinism and divergence detection.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "rbsim/builders.hpp"
#include "test_util.hpp"

namespace rbsim {
namespace {

using test::make_world;
using test::same_bits;

// ---------------------------------------------------------------------------------------------
// Free fall. With constant acceleration g both methods have exact discrete solutions:
//   V_n = V0 + n h g
//   explicit:   X_n = X0 + V0 n h + g h^2 n (n - 1) / 2   (positions use the old velocity)
//   symplectic: X_n = X0 + V0 n h + g h^2 n (n + 1) / 2   (positions use the new velocity)
struct FreeFallCase {
  Integrator integrator;
  double sign;  // -1 for n (n - 1), +1 for n (n + 1)
};

void PrintTo(const FreeFallCase& c, std::ostream* os) {
  *os << to_string(c.integrator);
}

class WorldStepFreeFall : public ::testing::TestWithParam<FreeFallCase> {};

TEST_P(WorldStepFreeFall, MatchesDiscreteClosedForm) {
  const double h = 0.01;
  const Vec2 g(0.75, -9.81), v0(1.0, 2.0), x0(0.0, 10.0);
  World w = make_world(builders::free_fall(GetParam().integrator, h, g, v0));
  for (int n = 1; n <= 1000; ++n) {
    w.step();
    const BodyState s = w.state(BodyId{0});
    const double dn = n;
    const Vec2 x = x0 + v0 * dn * h + g * (h * h * dn * (dn + GetParam().sign) / 2.0);
    const Vec2 v = v0 + g * (dn * h);
    ASSERT_NEAR(s.position.x(), x.x(), 1e-12 * (1.0 + std::abs(x.x()))) << "step " << n;
    ASSERT_NEAR(s.position.y(), x.y(), 1e-12 * (1.0 + std::abs(x.y()))) << "step " << n;
    ASSERT_NEAR(s.velocity.x(), v.x(), 1e-12 * (1.0 + std::abs(v.x()))) << "step " << n;
    ASSERT_NEAR(s.velocity.y(), v.y(), 1e-12 * (1.0 + std::abs(v.y()))) << "step " << n;
    ASSERT_EQ(s.theta, 0.0);
    ASSERT_EQ(s.omega, 0.0);
  }
  EXPECT_EQ(w.step_index(), 1000);
  EXPECT_NEAR(w.time(), 10.0, 1e-12);
}

// Against the continuum X0 + V0 t + g t^2 / 2 the error is exactly |g| h t / 2: first order.
TEST_P(WorldStepFreeFall, ConvergesToContinuumAtFirstOrder) {
  const Vec2 g(0.0, -9.81), v0(1.0, 2.0), x0(0.0, 10.0);
  const double t_end = 2.0;
  std::vector<double> errors;
  for (double h : {0.02, 0.01, 0.005}) {
    World w = make_world(builders::free_fall(GetParam().integrator, h, g, v0));
    const auto steps = static_cast<int>(std::lround(t_end / h));
    for (int i = 0; i < steps; ++i) w.step();
    const Vec2 exact = x0 + v0 * t_end + g * (t_end * t_end / 2.0);
    const double err = (w.state(BodyId{0}).position - exact).norm();
    EXPECT_NEAR(err, g.norm() * h * t_end / 2.0, 1e-9) << "h = " << h;
    // the sign of the error tells the two methods apart: explicit lags above, symplectic below
    EXPECT_GT(GetParam().sign * (exact.y() - w.state(BodyId{0}).position.y()), 0.0);
    errors.push_back(err);
  }
  EXPECT_NEAR(errors[0] / errors[1], 2.0, 1e-6);
  EXPECT_NEAR(errors[1] / errors[2], 2.0, 1e-6);
}

INSTANTIATE_TEST_SUITE_P(BothIntegrators, WorldStepFreeFall,
                         ::testing::Values(FreeFallCase{Integrator::ExplicitEuler, -1.0},
                                           FreeFallCase{Integrator::SymplecticEuler, +1.0}),
                         [](const auto& tp) {
                           return tp.param.integrator == Integrator::ExplicitEuler ? "Explicit"
                                                                                   : "Symplectic";
                         });

TEST(WorldStep, GravityForceIsMassTimesG) {
  World w = make_world(builders::free_fall(Integrator::SymplecticEuler, 0.01, {0.5, -9.81}));
  EXPECT_EQ(w.force(BodyId{0}), Vec2(0.0, 0.0));  // zero before the first step
  w.step();
  EXPECT_EQ(w.force(BodyId{0}), Vec2(4.0 * 0.5, 4.0 * -9.81));
  EXPECT_EQ(w.torque(BodyId{0}), 0.0);
}

// ---------------------------------------------------------------------------------------------
// Harmonic spring: a square (M = 4) on a spring through its centre of mass to a fixed point.
// u = x - l0 obeys u'' = -(k / M) u, period 2 pi sqrt(M / k).

// Times at which u = x - l0 crosses zero going downwards, by linear interpolation.
std::vector<double> downward_crossings(World& w, double l0, std::int64_t steps) {
  std::vector<double> times;
  double prev = w.state(BodyId{0}).position.x() - l0;
  for (std::int64_t i = 0; i < steps; ++i) {
    const double t0 = w.time();
    w.step();
    const double u = w.state(BodyId{0}).position.x() - l0;
    if (prev > 0.0 && u <= 0.0) times.push_back(t0 + w.dt() * prev / (prev - u));
    prev = u;
  }
  return times;
}

TEST(WorldStep, FixedSpringOscillatesWithAnalyticPeriod) {
  for (double k : {4.0, 1.0, 25.0}) {
    const double period = 2.0 * std::numbers::pi * std::sqrt(4.0 / k);
    const double dt = period / 5000.0;
    World w = make_world(builders::fixed_spring(Integrator::SymplecticEuler, dt, k, 1.0, 0.5));
    const auto crossings = downward_crossings(w, 1.0, static_cast<std::int64_t>(10.5 * 5000));
    ASSERT_GE(crossings.size(), 10u) << "k = " << k;
    const double measured =
        (crossings.back() - crossings.front()) / static_cast<double>(crossings.size() - 1);
    EXPECT_NEAR(measured / period, 1.0, 1e-3) << "k = " << k;
    // the motion stays on the spring's line: no sideways drift, no rotation
    EXPECT_EQ(w.state(BodyId{0}).position.y(), 0.0);
    EXPECT_EQ(w.state(BodyId{0}).theta, 0.0);
  }
}

TEST(WorldStep, FixedSpringFirstStepForceIsMinusKStretch) {
  World w = make_world(builders::fixed_spring(Integrator::SymplecticEuler, 0.01, 3.0, 1.0, 0.5));
  w.step();
  EXPECT_DOUBLE_EQ(w.force(BodyId{0}).x(), -3.0 * 0.5);  // pulls back towards the fixed point
  EXPECT_EQ(w.force(BodyId{0}).y(), 0.0);
  EXPECT_DOUBLE_EQ(w.spring_state(SpringId{0}).potential,
                   0.5 * 3.0 * std::pow(w.state(BodyId{0}).position.x() - 1.0, 2));
}

double spring_energy(const World& w) {
  return w.energy().total();
}

// Symplectic Euler exactly conserves the modified energy Q = v^2 + w^2 u^2 - h w^2 u v of the
// harmonic oscillator, so E stays within O(h w) of E0 forever. Explicit Euler multiplies
// v^2 + w^2 u^2 (hence E) by exactly (1 + h^2 w^2) every step.
TEST(WorldStep, SymplecticEnergyBoundedExplicitEnergyGrowsGeometrically) {
  const double k = 4.0, m = 4.0, h = 0.01, omega2 = k / m;  // w = 1, period 2 pi
  const auto steps_per_period = static_cast<std::int64_t>(2.0 * std::numbers::pi / h);

  World sym = make_world(builders::fixed_spring(Integrator::SymplecticEuler, h, k, 1.0, 0.5));
  const double e0 = spring_energy(sym);
  auto invariant = [&](const World& w) {
    const double u = w.state(BodyId{0}).position.x() - 1.0, v = w.state(BodyId{0}).velocity.x();
    return v * v + omega2 * u * u - h * omega2 * u * v;
  };
  const double q0 = invariant(sym);
  double first_dev = 0.0, last_dev = 0.0, worst_q = 0.0;
  const std::int64_t periods = 200;
  for (std::int64_t i = 0; i < periods * steps_per_period; ++i) {
    sym.step();
    const double dev = std::abs(spring_energy(sym) - e0) / e0;
    if (i < 10 * steps_per_period) first_dev = std::max(first_dev, dev);
    if (i >= (periods - 10) * steps_per_period) last_dev = std::max(last_dev, dev);
    worst_q = std::max(worst_q, std::abs(invariant(sym) - q0) / q0);
  }
  EXPECT_LT(worst_q, 1e-10);
  EXPECT_LT(last_dev, h);                        // bounded by O(h w) ...
  EXPECT_GT(last_dev, 1e-4 * h);                 // ... (and not trivially zero) ...
  EXPECT_NEAR(last_dev / first_dev, 1.0, 1e-2);  // ... with no secular growth

  World exp = make_world(builders::fixed_spring(Integrator::ExplicitEuler, h, k, 1.0, 0.5));
  const std::int64_t n = 10 * steps_per_period;
  for (std::int64_t i = 0; i < n; ++i) exp.step();
  const double growth = spring_energy(exp) / e0;
  EXPECT_NEAR(growth, std::pow(1.0 + h * h * omega2, static_cast<double>(n)), 1e-9);
  EXPECT_GT(growth, 1.8);  // 10 periods: e^(2 pi h w * 10 / ...) ~ 1.87
}

// ---------------------------------------------------------------------------------------------
// The update order on one step, by hand. Square (M = 4, I = 8) at the origin, V0 = (1, 2),
// omega0 = 0.5, h = 0.1, one spring from body anchor (1, 0) to the fixed point (1, 3), k = 2,
// l0 = 1: d = (0, 3), l = 3, F = k (l - l0) d / l = (0, 4), torque = (1, 0) x (0, 4) = 4.
// So dV = h F / M = (0, 0.1), d omega = h tau / I = 0.05.
WorldDef hand_example(Integrator integrator) {
  WorldDef def;
  def.integrator = integrator;
  def.dt = 0.1;
  def.bodies.push_back(builders::square({0.0, 0.0}, {1.0, 2.0}, 0.5));
  def.springs.push_back(test::spring(0, {1.0, 0.0}, kFixed, {1.0, 3.0}, 2.0, 1.0));
  return def;
}

TEST(WorldStep, ExplicitEulerMovesPositionsWithOldVelocities) {
  World w = make_world(hand_example(Integrator::ExplicitEuler));
  w.step();
  EXPECT_DOUBLE_EQ(w.force(BodyId{0}).x(), 0.0);
  EXPECT_DOUBLE_EQ(w.force(BodyId{0}).y(), 4.0);
  EXPECT_DOUBLE_EQ(w.torque(BodyId{0}), 4.0);
  const BodyState s = w.state(BodyId{0});
  EXPECT_DOUBLE_EQ(s.position.x(), 0.1);
  EXPECT_DOUBLE_EQ(s.position.y(), 0.2);
  EXPECT_DOUBLE_EQ(s.theta, 0.05);
  EXPECT_DOUBLE_EQ(s.velocity.x(), 1.0);
  EXPECT_DOUBLE_EQ(s.velocity.y(), 2.1);
  EXPECT_DOUBLE_EQ(s.omega, 0.55);
}

TEST(WorldStep, SymplecticEulerMovesPositionsWithNewVelocities) {
  World w = make_world(hand_example(Integrator::SymplecticEuler));
  w.step();
  const BodyState s = w.state(BodyId{0});
  EXPECT_DOUBLE_EQ(s.velocity.x(), 1.0);
  EXPECT_DOUBLE_EQ(s.velocity.y(), 2.1);
  EXPECT_DOUBLE_EQ(s.omega, 0.55);
  EXPECT_DOUBLE_EQ(s.position.x(), 0.1);
  EXPECT_DOUBLE_EQ(s.position.y(), 0.21);
  EXPECT_DOUBLE_EQ(s.theta, 0.055);
}

TEST(WorldStep, ForcesAreEvaluatedAtTheStartOfTheStep) {
  // Second step of the explicit example: the spring is evaluated at theta = 0.05, X = (0.1, 0.2).
  World w = make_world(hand_example(Integrator::ExplicitEuler));
  w.step();
  w.step();
  const double c = std::cos(0.05), s = std::sin(0.05);
  const Vec2 arm(c, s), ri = arm + Vec2(0.1, 0.2), d = Vec2(1.0, 3.0) - ri;
  const Vec2 f = 2.0 * (d.norm() - 1.0) * d / d.norm();
  EXPECT_NEAR(w.force(BodyId{0}).x(), f.x(), 1e-14);
  EXPECT_NEAR(w.force(BodyId{0}).y(), f.y(), 1e-14);
  EXPECT_NEAR(w.torque(BodyId{0}), test::cross(arm, f), 1e-14);
}

// ---------------------------------------------------------------------------------------------
bool bit_identical(const World& a, const World& b) {
  auto same = [](std::span<const double> x, std::span<const double> y) {
    return x.size() == y.size() && std::memcmp(x.data(), y.data(), x.size_bytes()) == 0;
  };
  return same(a.x(), b.x()) && same(a.y(), b.y()) && same(a.theta(), b.theta()) && same(a.vx(), b.vx()) &&
         same(a.vy(), b.vy()) && same(a.omega(), b.omega());
}

TEST(WorldStep, SameDefinitionTwiceGivesBitIdenticalStates) {
  for (bool distinct : {true, false}) {
    const WorldDef def = builders::grid(64, true, distinct);
    World a = make_world(def);
    World b = make_world(def);
    for (int i = 0; i < 500; ++i) {
      a.step();
      b.step();
      ASSERT_TRUE(bit_identical(a, b)) << "step " << i;
    }
    // and something actually moved
    const World fresh = make_world(def);
    EXPECT_NE(a.x()[0], fresh.x()[0]);
    EXPECT_NE(a.theta()[5], fresh.theta()[5]);
    // a world built later, stepped the same number of times, agrees too
    World c = make_world(def);
    for (int i = 0; i < 500; ++i) c.step();
    EXPECT_TRUE(bit_identical(a, c));
  }
}

TEST(WorldSetState, RestartFromRecordedStateReproducesTheRun) {
  const WorldDef def = builders::grid(9, true, true);
  World a = make_world(def);
  for (int i = 0; i < 100; ++i) a.step();
  World b = make_world(def);
  for (std::int32_t k = 0; k < a.body_count(); ++k) b.set_state(BodyId{k}, a.state(BodyId{k}));
  b.set_step_index(a.step_index());
  for (int i = 0; i < 100; ++i) {
    a.step();
    b.step();
  }
  EXPECT_TRUE(bit_identical(a, b));
  EXPECT_EQ(a.step_index(), b.step_index());
  EXPECT_EQ(b.time(), 200 * def.dt);
}

// ---------------------------------------------------------------------------------------------
TEST(WorldFindNonfinite, DetectsDivergingStiffExplicitSpring) {
  // explicit Euler on a spring with h w = 0.1 * sqrt(1e6 / 4) = 50: unstable, blows up fast
  World w = make_world(builders::fixed_spring(Integrator::ExplicitEuler, 0.1, 1e6, 1.0, 0.5));
  EXPECT_FALSE(w.find_nonfinite().has_value());
  std::optional<World::NonFinite> bad;
  int steps = 0;
  while (!bad && steps < 100000) {
    const BodyState before = w.state(BodyId{0});
    w.step();
    ++steps;
    bad = w.find_nonfinite();
    if (bad) {
      // the state before this step was still finite: it is caught at the first bad step
      EXPECT_TRUE(std::isfinite(before.position.x()) && std::isfinite(before.velocity.x()));
    }
  }
  ASSERT_TRUE(bad.has_value()) << "no divergence after " << steps << " steps";
  EXPECT_LT(steps, 1000);
  EXPECT_EQ(bad->body.index, 0);
  // The derived quantities overflow first (T = M V^2 / 2, U = k stretch^2 / 2) and are caught
  // while the state itself is still finite.
  const std::string q = bad->quantity;
  EXPECT_TRUE(q == "x" || q == "vx" || q == "px" || q == "T_point" || q == "U_spring" || q == "E") << q;
}

TEST(WorldFindNonfinite, NamesTheBodyAndQuantity) {
  const char* names[] = {"x", "y", "theta", "vx", "vy", "omega"};
  for (int q = 0; q < 6; ++q) {
    for (double bad : {std::nan(""), static_cast<double>(INFINITY), -static_cast<double>(INFINITY)}) {
      World w = make_world(builders::free_bodies(Integrator::SymplecticEuler, 0.01, 3));
      BodyState s = w.state(BodyId{2});
      double* fields[] = {&s.position.x(), &s.position.y(), &s.theta,
                          &s.velocity.x(), &s.velocity.y(), &s.omega};
      *fields[q] = bad;
      w.set_state(BodyId{2}, s);
      const auto found = w.find_nonfinite();
      ASSERT_TRUE(found.has_value()) << names[q] << " = " << bad;
      EXPECT_EQ(found->body.index, 2);
      EXPECT_STREQ(found->quantity, names[q]);
    }
  }
  // huge values whose derived quantities stay finite are not flagged
  World w = make_world(builders::free_bodies(Integrator::SymplecticEuler, 0.01, 2));
  BodyState s = w.state(BodyId{1});
  s.position = {1e150, -1e150};
  s.omega = 1e150;
  w.set_state(BodyId{1}, s);
  EXPECT_FALSE(w.find_nonfinite().has_value());
  // a finite state whose kinetic energy overflows is flagged, naming the quantity
  s.position = {0.0, 0.0};
  s.omega = 0.0;
  s.velocity = {1e200, 0.0};
  w.set_state(BodyId{1}, s);
  const auto found = w.find_nonfinite();
  ASSERT_TRUE(found.has_value());
  EXPECT_EQ(found->body.index, 1);
  EXPECT_STREQ(found->quantity, "T_point");
}

}  // namespace
}  // namespace rbsim

namespace rbsim {
namespace {

TEST(WorldVelocitiesWithin, EveryLaneAndTheTailAgainstTheLimit) {
  // 7 bodies: two SIMD iterations of 4 values would miss none, and 3 values go through the tail.
  for (std::int32_t body = 0; body < 7; ++body) {
    for (int q = 0; q < 3; ++q) {
      for (double bad :
           {2.5, -2.5, std::nan(""), static_cast<double>(INFINITY), -static_cast<double>(INFINITY)}) {
        World w = make_world(builders::free_bodies(Integrator::SymplecticEuler, 0.01, 7));
        for (std::int32_t b = 0; b < 7; ++b) {
          BodyState s = w.state(BodyId{b});
          s.velocity = {1.0, -1.0};
          s.omega = 0.5;
          w.set_state(BodyId{b}, s);
        }
        EXPECT_TRUE(w.velocities_within(2.0));
        BodyState s = w.state(BodyId{body});
        double* fields[] = {&s.velocity.x(), &s.velocity.y(), &s.omega};
        *fields[q] = bad;
        w.set_state(BodyId{body}, s);
        EXPECT_FALSE(w.velocities_within(2.0)) << "body " << body << " value " << q << " = " << bad;
        EXPECT_TRUE(w.velocities_within(3.0) || !std::isfinite(bad));
        EXPECT_EQ(std::isnan(bad), std::isnan(w.peak_velocity()));
      }
    }
  }
}

TEST(WorldFiniteBound, KeepsEveryDerivedQuantityFinite) {
  World w = make_world(builders::grid(50, true));
  const double bound = w.finite_bound();
  EXPECT_GT(bound, 1e100);  // ordinary scenes never leave the cheap check
  // Every state value at the bound, with the signs that add up: still nothing non-finite.
  for (std::int32_t b = 0; b < w.body_count(); ++b) {
    w.set_state(BodyId{b}, BodyState{{bound, -bound}, bound, {-bound, bound}, bound});
  }
  EXPECT_FALSE(w.find_nonfinite().has_value());
  // Absurd masses leave no room: every check is then exact.
  WorldDef heavy = builders::free_bodies(Integrator::SymplecticEuler, 0.01, 2);
  for (BodyDef& body : heavy.bodies) {
    for (double& m : body.masses) m = 1e300;
  }
  EXPECT_EQ(make_world(heavy).finite_bound(), 0.0);
}

}  // namespace
}  // namespace rbsim
