// Wind (docs/rigid-body-milestone.md 4.8): the closed form against the spec's sample sum, and its physical
// behaviour.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <numbers>
#include <random>

#include "rbsim/builders.hpp"
#include "test_util.hpp"

namespace rbsim {
namespace {

using test::cross;
using test::make_world;
using test::perp;

struct Sampled {
  Vec2 force{0.0, 0.0};
  double torque = 0.0;
  double force_scale = 0.0, torque_scale = 0.0;  // sums of |terms|, for relative tolerances
  double power = 0.0;                            // sum f_j . (v_j - w) <= 0
};

// The spec formula, sample by sample: edge i from vertex i to i + 1 (world space), points at
// (k + 1/2) / P along it, n = (-e.y, e.x) / |e|,  f = beta (l / P) ((w - v_j) . n) n,
// v_j = V + omega J (p - X), torque = sum (p - X) x f.
Sampled brute_force(const World& world, BodyId b, const WindDef& wind) {
  Sampled out;
  const BodyState s = world.state(b);
  const auto count = static_cast<std::int32_t>(world.hull(b).size());
  const int p_count = wind.points_per_edge;
  for (std::int32_t i = 0; i < count; ++i) {
    const Vec2 a = world.world_vertex(b, i), e = world.world_vertex(b, (i + 1) % count) - a;
    const double l = e.norm();
    if (l == 0.0) continue;  // weight l / P = 0; its normal is undefined
    const Vec2 n = Vec2(-e.y(), e.x()) / l;
    for (int k = 0; k < p_count; ++k) {
      const Vec2 p = a + ((k + 0.5) / p_count) * e;
      const Vec2 v = s.velocity + s.omega * perp(p - s.position);
      const Vec2 f = wind.beta * (l / p_count) * (wind.velocity - v).dot(n) * n;
      out.force += f;
      out.torque += cross(p - s.position, f);
      out.force_scale += f.norm();
      out.torque_scale += std::abs(cross(p - s.position, f));
      out.power += f.dot(v - wind.velocity);
    }
  }
  return out;
}

BodyDef random_hull(std::mt19937_64& rng, int vertices) {
  std::uniform_real_distribution<double> pos(-2.0, 2.0), mass(0.5, 2.0);
  BodyDef b;
  for (int v = 0; v < vertices; ++v) {
    b.hull.emplace_back(pos(rng), pos(rng));
    b.masses.push_back(mass(rng));
  }
  return b;
}

TEST(WorldStepWind, ClosedFormEqualsSampleSumForRandomHulls) {
  std::mt19937_64 rng(20240607);
  std::uniform_real_distribution<double> u(-3.0, 3.0), angle(-std::numbers::pi, std::numbers::pi),
      pos_beta(0.1, 2.0);
  int checked = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const int points = std::array{2, 3, 7}[trial % 3];
    WorldDef def;
    def.dt = 1e-3;
    def.integrator = trial % 2 ? Integrator::ExplicitEuler : Integrator::SymplecticEuler;
    // several bodies, two of them with the same shape (one shared set of wind moments)
    BodyDef shared = random_hull(rng, 2 + trial % 7);
    def.bodies.push_back(shared);
    def.bodies.push_back(random_hull(rng, 3 + trial % 5));
    for (Vec2& v : shared.hull) v += Vec2(8.0, -4.0);
    def.bodies.push_back(shared);
    def.winds.push_back(test::wind(pos_beta(rng), {u(rng), u(rng)}, points));
    if (trial % 4 == 0)
      def.winds.push_back(test::wind(pos_beta(rng), {u(rng), u(rng)}, std::array{2, 3, 7}[(trial + 1) % 3]));
    Result<World> created = World::create(def);
    ASSERT_TRUE(created) << created.error().message;
    World w = std::move(created.value());
    for (std::int32_t b = 0; b < w.body_count(); ++b) {
      w.set_state(BodyId{b}, BodyState{{u(rng), u(rng)}, angle(rng), {u(rng), u(rng)}, u(rng)});
    }
    std::vector<Sampled> expected(static_cast<std::size_t>(w.body_count()));
    for (std::int32_t b = 0; b < w.body_count(); ++b) {
      for (const WindDef& wind : def.winds) {
        const Sampled s = brute_force(w, BodyId{b}, wind);
        Sampled& e = expected[b];
        e.force += s.force;
        e.torque += s.torque;
        e.force_scale += s.force_scale;
        e.torque_scale += s.torque_scale;
        EXPECT_LE(s.power, 1e-12 * s.force_scale) << "wind must dissipate relative motion";
      }
    }
    w.step();  // forces are those of the state before the step
    for (std::int32_t b = 0; b < w.body_count(); ++b) {
      const Sampled& e = expected[b];
      const double ftol = 1e-12 * e.force_scale, ttol = 1e-12 * e.torque_scale;
      EXPECT_NEAR(w.force(BodyId{b}).x(), e.force.x(), ftol)
          << "trial " << trial << " body " << b << " P " << points;
      EXPECT_NEAR(w.force(BodyId{b}).y(), e.force.y(), ftol)
          << "trial " << trial << " body " << b << " P " << points;
      EXPECT_NEAR(w.torque(BodyId{b}), e.torque, ttol)
          << "trial " << trial << " body " << b << " P " << points;
      ++checked;
    }
  }
  EXPECT_EQ(checked, 900);
}

TEST(WorldStepWind, ZeroLengthEdgesCarryNoWeight) {
  WorldDef a;
  a.bodies.push_back(builders::square({0.0, 0.0}, {0.2, -0.1}, 0.7));
  a.winds.push_back(test::wind(1.3, {1.0, 2.0}, 3));
  WorldDef b = a;
  b.bodies[0].hull.insert(b.bodies[0].hull.begin() + 2, b.bodies[0].hull[1]);  // duplicate vertex 1
  b.bodies[0].masses.insert(b.bodies[0].masses.begin() + 2, 1e-300);
  World wa = make_world(a), wb = make_world(b);
  wa.step();
  wb.step();
  EXPECT_FALSE(wb.find_nonfinite().has_value());
  EXPECT_NEAR((wa.force(BodyId{0}) - wb.force(BodyId{0})).norm(), 0.0, 1e-12);
  EXPECT_NEAR(wa.torque(BodyId{0}), wb.torque(BodyId{0}), 1e-12);
}

// The 2 x 2 square: A = sum l n n^T = 4 Id, so F = 4 beta (w - V), dV/dt = beta (w - V) and
// both integrators give V_n - w = (1 - h beta)^n (V0 - w) exactly; the square feels no torque.
TEST(WorldStepWind, SquareRelaxesToWindSpeedGeometrically) {
  for (Integrator integrator : {Integrator::ExplicitEuler, Integrator::SymplecticEuler}) {
    for (int points : {2, 5}) {
      const double h = 0.01, beta = 0.8;
      const Vec2 wind(1.5, -0.5);
      World w = make_world(builders::square_in_wind(integrator, h, wind, beta, points));
      for (int n = 1; n <= 2000; ++n) {
        w.step();
        const Vec2 expected = wind + std::pow(1.0 - h * beta, n) * (Vec2(0.0, 0.0) - wind);
        ASSERT_NEAR(w.state(BodyId{0}).velocity.x(), expected.x(), 1e-12) << n;
        ASSERT_NEAR(w.state(BodyId{0}).velocity.y(), expected.y(), 1e-12) << n;
        ASSERT_EQ(w.state(BodyId{0}).omega, 0.0) << n;
      }
      EXPECT_LT((w.state(BodyId{0}).velocity - wind).norm(), 1e-6);
    }
  }
}

// A spinning, symmetric body (regular hexagon) dropped into wind: it ends up moving with the
// wind and not rotating.
TEST(WorldStepWind, SymmetricBodyReachesWindVelocityAndStopsSpinning) {
  WorldDef def;
  def.dt = 0.01;
  def.integrator = Integrator::SymplecticEuler;
  def.bodies.push_back(builders::polygon(6, 1.0, {0.0, 0.0}, {0.0, 0.0}, 3.0));
  const Vec2 wind(-2.0, 1.0);
  def.winds.push_back(test::wind(10.0, wind, 4));  // spin decays at beta l^3 (1 - 1/P^2) / 2 / I = 0.78 / s
  World w = make_world(def);
  double last_omega = 3.0;
  for (int i = 0; i < 5000; ++i) {
    w.step();
    const double om = w.state(BodyId{0}).omega;
    ASSERT_GE(om, 0.0) << "spin overshot at step " << i;
    ASSERT_LE(om, last_omega) << "spin grew at step " << i;
    last_omega = om;
  }
  EXPECT_LT((w.state(BodyId{0}).velocity - wind).norm(), 1e-9);
  EXPECT_LT(std::abs(w.state(BodyId{0}).omega), 1e-9);
}

// Torque from spin alone is -beta omega sum (l / P) ((p - X) x n)^2: it opposes the spin for any
// hull; in still air the force on a spinning square is zero.
TEST(WorldStepWind, TorqueOpposesSpin) {
  std::mt19937_64 rng(7);
  for (double omega : {2.0, -2.0, 0.01, -50.0}) {
    World sq = make_world(builders::square_in_wind(Integrator::SymplecticEuler, 0.01, {0.0, 0.0}, 1.0, 3));
    sq.set_state(BodyId{0}, BodyState{{0.0, 0.0}, 0.3, {0.0, 0.0}, omega});
    sq.step();
    EXPECT_LT(sq.torque(BodyId{0}) * omega, 0.0) << omega;
    EXPECT_NEAR(sq.force(BodyId{0}).norm(), 0.0, 1e-12 * std::abs(omega));
    EXPECT_LT(std::abs(sq.state(BodyId{0}).omega), std::abs(omega));
    for (int trial = 0; trial < 20; ++trial) {
      WorldDef def;
      def.dt = 1e-3;
      def.bodies.push_back(random_hull(rng, 3 + trial % 5));
      def.winds.push_back(test::wind(0.7, {0.0, 0.0}, 2 + trial % 3));
      World w = make_world(def);
      w.set_state(BodyId{0}, BodyState{w.state(BodyId{0}).position, 1.0 * trial, {0.0, 0.0}, omega});
      w.step();
      EXPECT_LT(w.torque(BodyId{0}) * omega, 0.0) << "omega " << omega << " trial " << trial;
    }
  }
}

// A body at rest is pushed along the wind (F . w > 0 since A is positive semi-definite) and the
// force is proportional to beta.
TEST(WorldStepWind, BodyAtRestIsPushedDownwindProportionallyToBeta) {
  std::mt19937_64 rng(99);
  for (int trial = 0; trial < 30; ++trial) {
    const Vec2 wind(std::cos(trial * 0.7), std::sin(trial * 0.7));
    WorldDef def;
    def.bodies.push_back(random_hull(rng, 3 + trial % 4));
    def.winds.push_back(test::wind(1.0, wind, 2));
    WorldDef doubled = def;
    doubled.winds[0].beta = 2.0;
    World a = make_world(def), b = make_world(doubled);
    a.step();
    b.step();
    EXPECT_GT(a.force(BodyId{0}).dot(wind), 0.0) << trial;
    EXPECT_NEAR((b.force(BodyId{0}) - 2.0 * a.force(BodyId{0})).norm(), 0.0,
                1e-12 * b.force(BodyId{0}).norm());
    EXPECT_NEAR(b.torque(BodyId{0}), 2.0 * a.torque(BodyId{0}),
                1e-12 * (1.0 + std::abs(b.torque(BodyId{0}))));
  }
}

}  // namespace
}  // namespace rbsim
