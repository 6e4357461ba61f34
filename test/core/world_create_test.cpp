// World::create validates its definition.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <string>

#include "rbsim/builders.hpp"
#include "test_util.hpp"

namespace rbsim {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// A valid world with every kind of force, which each case below breaks in one way.
WorldDef valid() {
  WorldDef def;
  def.dt = 0.01;
  def.bodies.push_back(builders::square({0.0, 0.0}, {1.0, 0.0}, 0.5));
  def.bodies.push_back(builders::polygon(5, 1.0, {4.0, 0.0}));
  def.springs.push_back(test::spring(0, {1.0, 0.0}, 1, {-1.0, 0.0}, 2.0, 1.0));
  def.springs.push_back(test::spring(kFixed, {0.0, 5.0}, 0, {0.0, 0.0}, 1.0, 0.0));
  def.gravity.push_back(GravityDef{{0.0, -9.81}});
  def.winds.push_back(test::wind(1.0, {1.0, 0.0}, 2));
  return def;
}

struct InvalidCase {
  const char* name;
  std::function<void(WorldDef&)> breaks;
  const char* expected;  // a piece of the message
};

void PrintTo(const InvalidCase& c, std::ostream* os) {
  *os << c.name;
}

class WorldCreateRejects : public ::testing::TestWithParam<InvalidCase> {};

TEST_P(WorldCreateRejects, InvalidDefinition) {
  WorldDef def = valid();
  GetParam().breaks(def);
  const Result<World> w = World::create(def);
  ASSERT_FALSE(w.ok()) << GetParam().name;
  EXPECT_NE(w.error().message.find(GetParam().expected), std::string::npos)
      << GetParam().name << ": " << w.error().message;
  EXPECT_EQ(w.error().message.rfind("invalid world: ", 0), 0u) << w.error().message;
  EXPECT_EQ(w.error().message.find('\n'), std::string::npos);
}

const InvalidCase kInvalid[] = {
    {"dt_zero", [](WorldDef& d) { d.dt = 0.0; }, "dt"},
    {"dt_negative", [](WorldDef& d) { d.dt = -0.01; }, "dt"},
    {"dt_nan", [](WorldDef& d) { d.dt = kNaN; }, "dt"},
    {"dt_inf", [](WorldDef& d) { d.dt = kInf; }, "dt"},
    {"mass_zero", [](WorldDef& d) { d.bodies[1].masses[2] = 0.0; }, "body 1: vertex mass must be > 0"},
    {"mass_negative", [](WorldDef& d) { d.bodies[0].masses[0] = -1.0; }, "body 0: vertex mass must be > 0"},
    {"mass_nan", [](WorldDef& d) { d.bodies[0].masses[3] = kNaN; }, "mass"},
    {"no_vertices", [](WorldDef& d) { d.bodies[0].hull.clear(), d.bodies[0].masses.clear(); }, "at least 2"},
    {"one_vertex", [](WorldDef& d) { d.bodies[1].hull.resize(1), d.bodies[1].masses.resize(1); },
     "body 1: needs at least 2"},
    {"mass_count_mismatch", [](WorldDef& d) { d.bodies[0].masses.pop_back(); }, "one mass per hull vertex"},
    {"coincident_vertices",
     [](WorldDef& d) { d.bodies[1].hull.assign(d.bodies[1].hull.size(), Vec2(2.0, 3.0)); },
     "body 1: all vertices coincide"},
    {"vertex_nan", [](WorldDef& d) { d.bodies[0].hull[1].y() = kNaN; }, "vertex position not finite"},
    {"vertex_inf", [](WorldDef& d) { d.bodies[0].hull[1].x() = -kInf; }, "vertex position not finite"},
    {"velocity_nan", [](WorldDef& d) { d.bodies[0].velocity.x() = kNaN; }, "velocity not finite"},
    {"omega_inf", [](WorldDef& d) { d.bodies[1].omega = kInf; }, "body 1: velocity not finite"},
    {"radius_zero", [](WorldDef& d) { d.bodies[0].radius = 0.0; }, "radius"},
    {"spring_i_out_of_range", [](WorldDef& d) { d.springs[0].body_i = 2; },
     "spring 0: body index out of range"},
    {"spring_j_out_of_range", [](WorldDef& d) { d.springs[1].body_j = 7; },
     "spring 1: body index out of range"},
    {"spring_index_minus_two", [](WorldDef& d) { d.springs[0].body_j = -2; }, "body index out of range"},
    {"spring_anchor_nan", [](WorldDef& d) { d.springs[1].anchor_i.x() = kNaN; }, "anchor not finite"},
    {"spring_k_negative", [](WorldDef& d) { d.springs[0].stiffness = -1.0; }, "k must be >= 0"},
    {"spring_k_nan", [](WorldDef& d) { d.springs[0].stiffness = kNaN; }, "k must be >= 0"},
    {"spring_l0_negative", [](WorldDef& d) { d.springs[0].rest_length = -0.5; }, "l0 must be >= 0"},
    {"gravity_nan", [](WorldDef& d) { d.gravity[0].acceleration.y() = kNaN; }, "gravity not finite"},
    {"wind_beta_negative", [](WorldDef& d) { d.winds[0].beta = -1.0; }, "beta"},
    {"wind_velocity_inf", [](WorldDef& d) { d.winds[0].velocity.x() = kInf; }, "wind velocity not finite"},
    {"wind_points_zero", [](WorldDef& d) { d.winds[0].points_per_edge = 0; }, "points per edge"},
};

INSTANTIATE_TEST_SUITE_P(Table, WorldCreateRejects, ::testing::ValuesIn(kInvalid),
                         [](const auto& tp) { return std::string(tp.param.name); });

TEST(WorldCreate, AcceptsTheValidDefinitionAndItsEdgeCases) {
  EXPECT_TRUE(World::create(valid()).ok());
  WorldDef def = valid();
  def.springs[0].body_i = kFixed;  // -1 on either end
  def.springs[0].body_j = kFixed;
  def.springs[0].stiffness = 0.0;  // k = 0, l0 = 0 and beta = 0 are allowed
  def.springs[0].rest_length = 0.0;
  def.winds[0].beta = 0.0;
  def.bodies[0].hull[1] = def.bodies[0].hull[0];  // some (not all) vertices coincide
  Result<World> w = World::create(def);
  ASSERT_TRUE(w.ok()) << w.error().message;
  EXPECT_EQ(w->body_count(), 2);
  EXPECT_EQ(w->spring_count(), 2);
  EXPECT_EQ(w->step_index(), 0);
  EXPECT_EQ(w->integrator(), Integrator::SymplecticEuler);
  EXPECT_EQ(w->dt(), 0.01);
  EXPECT_EQ(w->gravity().size(), 1u);
  EXPECT_EQ(w->winds().size(), 1u);
  EXPECT_GT(w->memory_bytes(), 0u);
}

TEST(WorldCreate, IntegratorNames) {
  EXPECT_STREQ(to_string(Integrator::ExplicitEuler), "explicit-euler");
  EXPECT_STREQ(to_string(Integrator::SymplecticEuler), "symplectic-euler");
}

}  // namespace
}  // namespace rbsim
