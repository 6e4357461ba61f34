// World::validate(): the invariants of the state arrays at a step boundary hold for every world
// create() makes and every step leaves, and a broken one is named; step() asserts them where
// assertions are on (Debug builds, the sanitizer stage).
#include <gtest/gtest.h>

#include <string>

#include "rbsim/builders.hpp"
#include "test_util.hpp"

namespace rbsim {
namespace {

using test::make_world;

TEST(WorldValidate, HoldsForCreatedWorldsAndAfterSteps) {
  for (const WorldDef& def : {builders::grid(40, true), builders::grid(10, false),
                              builders::fixed_spring(Integrator::ExplicitEuler, 0.01, 5.0),
                              builders::square_in_wind(Integrator::SymplecticEuler, 0.01, {1.0, 0.5})}) {
    World world = make_world(def);
    EXPECT_TRUE(world.validate().ok()) << world.validate().error().message;
    for (int k = 0; k < 20; ++k) world.step();
    EXPECT_TRUE(world.validate().ok()) << world.validate().error().message;
  }
}

TEST(WorldValidate, NamesThetaWrittenWithoutSyncRotations) {
  World world = make_world(builders::grid(4, true));
  world.state_columns().theta[2] += 0.25;
  const Status st = world.validate();
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.error().message.find("body 2: cos/sin are not those of theta"), std::string::npos)
      << st.error().message;
  world.sync_rotations();
  EXPECT_TRUE(world.validate().ok());
}

TEST(WorldValidate, NamesANegativeStepIndex) {
  World world = make_world(builders::grid(2, false));
  world.set_step_index(-3);
  const Status st = world.validate();
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.error().message.find("negative step index -3"), std::string::npos) << st.error().message;
}

TEST(WorldValidateDeathTest, StepAssertsTheInvariants) {
#ifdef NDEBUG
  GTEST_SKIP() << "assertions are off in this build (NDEBUG); the sanitizer stage runs this test";
#else
  World world = make_world(builders::grid(4, true));
  world.state_columns().theta[1] = 1.0;
  EXPECT_DEATH(world.step(), "internal error: the world's arrays hold their invariants at a step boundary");
#endif
}

}  // namespace
}  // namespace rbsim
