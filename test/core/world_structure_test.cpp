// Structural changes between steps (World::add_body, add_spring, remove_body, remove_spring): each
// against a world created from the edited definition and set to the same state at the same step,
// bit for bit; handles and ids across removals; shapes under churn; refusals that change nothing.
#include <gtest/gtest.h>

#include <cstring>
#include <limits>
#include <vector>

#include "rbsim/builders.hpp"
#include "test_util.hpp"

namespace rbsim {
namespace {

using test::make_world;
using test::same_bits;

bool same_column(std::span<const double> a, std::span<const double> b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}

// Every state column, the forces of the last step (once both have stepped) and the scene-wide
// sums, bit for bit.
void expect_same_world(const World& a, const World& b, int step, bool forces = true) {
  ASSERT_EQ(a.body_count(), b.body_count()) << "step " << step;
  ASSERT_EQ(a.spring_count(), b.spring_count()) << "step " << step;
  ASSERT_EQ(a.step_index(), b.step_index());
  EXPECT_TRUE(same_column(a.x(), b.x()) && same_column(a.y(), b.y()) && same_column(a.theta(), b.theta()) &&
              same_column(a.vx(), b.vx()) && same_column(a.vy(), b.vy()) && same_column(a.omega(), b.omega()))
      << "state differs at step " << step;
  for (std::int32_t i = 0; forces && i < a.body_count(); ++i) {
    ASSERT_TRUE(same_bits(a.force(BodyId{i}).x(), b.force(BodyId{i}).x()) &&
                same_bits(a.torque(BodyId{i}), b.torque(BodyId{i})))
        << "force on body " << i << " at step " << step;
  }
  const Energy ea = a.energy(), eb = b.energy();
  EXPECT_TRUE(same_bits(ea.u_gravity, eb.u_gravity) && same_bits(ea.u_spring, eb.u_spring) &&
              same_bits(ea.t_point, eb.t_point) && same_bits(ea.t_spin, eb.t_spin))
      << "energy at step " << step;
  const SceneTotals ta = a.totals(), tb = b.totals();
  EXPECT_TRUE(same_bits(ta.angular, tb.angular) && same_bits(ta.momentum.x(), tb.momentum.x()));
  EXPECT_TRUE(same_bits(a.finite_bound(), b.finite_bound()));
}

void step_both(World& a, World& b, int steps) {
  for (int k = 0; k < steps; ++k) {
    a.step();
    b.step();
    expect_same_world(a, b, static_cast<int>(a.step_index()));
    if (::testing::Test::HasFailure()) return;
  }
}

// Gravity, wind and springs between bodies and to fixed points, every hull its own shape.
WorldDef busy_world() {
  WorldDef def = builders::grid(5, true);
  def.springs.push_back(SpringDef{kFixed, 2, {1.0, 4.0}, {0.2, -0.1}, 3.0, 0.5});
  return def;
}

// The oracle: `def` created afresh, every body set to `states` (in the new order) at step k.
World oracle(const WorldDef& def, const std::vector<BodyState>& states, std::int64_t k) {
  World w = make_world(def);
  for (std::int32_t b = 0; b < w.body_count(); ++b) w.set_state(BodyId{b}, states[b]);
  w.set_step_index(k);
  return w;
}

std::vector<BodyState> states_of(const World& w) {
  std::vector<BodyState> out;
  for (std::int32_t b = 0; b < w.body_count(); ++b) out.push_back(w.state(BodyId{b}));
  return out;
}

TEST(WorldAddBody, StepsAsTheEditedDefinitionSetToTheSameStateBitForBit) {
  const WorldDef def = busy_world();
  World live = make_world(def);
  for (int k = 0; k < 23; ++k) live.step();

  // A heptagon written in its own frame, placed by a pose, with a spring to scene body 1.
  const BodyDef added = builders::polygon(7, 0.8, {0.3, -0.2});
  const BodyState pose{{4.0, 7.5}, 0.7, {-0.4, 0.25}, 1.3};
  const Result<BodyHandle> h = live.add_body(added, pose);
  ASSERT_TRUE(h.ok()) << h.error().message;
  const SpringDef spring{5, 1, {0.1, 0.2}, {-0.3, 0.0}, 7.0, 1.5};
  const Result<std::int32_t> spring_id = live.add_spring(spring);
  ASSERT_TRUE(spring_id.ok());
  EXPECT_EQ(spring_id.value(), def.springs.size());
  EXPECT_EQ(live.body_id(BodyId{5}), 5);
  ASSERT_TRUE(live.validate().ok()) << live.validate().error().message;

  WorldDef edited = def;
  edited.bodies.push_back(added);
  edited.springs.push_back(spring);
  World expected = oracle(edited, states_of(live), live.step_index());
  expect_same_world(live, expected, 23, false);
  step_both(live, expected, 60);
}

TEST(WorldRemoveBody, StepsAsTheEditedDefinitionAndNamesTheSpringsItTook) {
  const WorldDef def = busy_world();
  World live = make_world(def);
  for (int k = 0; k < 17; ++k) live.step();

  // Body 2 has three springs: 1 -> 2, 2 -> 3, and the extra one from a fixed point.
  std::vector<std::int32_t> removed;
  const BodyHandle doomed = live.handle(BodyId{2});
  std::vector<BodyState> states = states_of(live);
  ASSERT_TRUE(live.remove_body(doomed, &removed).ok());
  EXPECT_EQ(removed, (std::vector<std::int32_t>{1, 2, 5}));
  EXPECT_EQ(live.body_count(), 4);
  EXPECT_EQ(std::vector<std::int32_t>(live.body_ids().begin(), live.body_ids().end()),
            (std::vector<std::int32_t>{0, 1, 3, 4}));
  EXPECT_EQ(std::vector<std::int32_t>(live.spring_ids().begin(), live.spring_ids().end()),
            (std::vector<std::int32_t>{0, 3, 4}));
  EXPECT_FALSE(live.find(doomed).has_value());
  ASSERT_TRUE(live.validate().ok()) << live.validate().error().message;

  WorldDef edited = def;
  edited.bodies.erase(edited.bodies.begin() + 2);
  edited.springs = {def.springs[0], def.springs[3], def.springs[4]};
  for (SpringDef& s : edited.springs) {
    for (std::int32_t* end : {&s.body_i, &s.body_j}) {
      if (*end > 2) --*end;
    }
  }
  states.erase(states.begin() + 2);
  World expected = oracle(edited, states, live.step_index());
  expect_same_world(live, expected, 17, false);
  step_both(live, expected, 60);
}

TEST(WorldRemoveSpring, StepsAsTheEditedDefinition) {
  const WorldDef def = busy_world();
  World live = make_world(def);
  for (int k = 0; k < 9; ++k) live.step();
  ASSERT_TRUE(live.remove_spring(3).ok());
  EXPECT_FALSE(live.remove_spring(3).ok());  // gone, and its id is never given again
  WorldDef edited = def;
  edited.springs.erase(edited.springs.begin() + 3);
  World expected = oracle(edited, states_of(live), live.step_index());
  step_both(live, expected, 40);
}

TEST(WorldAddSpring, TheFirstSpringBringsTheRotationsUpToDate) {
  // No springs and no wind: cos/sin are not kept while nothing reads them.
  WorldDef def = builders::free_bodies(Integrator::SymplecticEuler, 0.01, 3);
  World live = make_world(def);
  for (int k = 0; k < 31; ++k) live.step();
  const SpringDef spring{0, 2, {0.5, 0.0}, {0.0, 0.5}, 4.0, 1.0};
  ASSERT_TRUE(live.add_spring(spring).ok());
  ASSERT_TRUE(live.validate().ok()) << live.validate().error().message;
  def.springs.push_back(spring);
  World expected = oracle(def, states_of(live), live.step_index());
  step_both(live, expected, 30);
}

TEST(WorldHandles, ARemovedBodysHandleNeverFindsAnotherBody) {
  World w = make_world(builders::free_bodies(Integrator::SymplecticEuler, 0.01, 3));
  const BodyDef hull = builders::square({0.0, 0.0});
  const BodyHandle a = w.add_body(hull, BodyState{}).value();
  EXPECT_EQ(a.index1, 4);
  EXPECT_EQ(w.body_id(*w.find(a)), 3);
  ASSERT_TRUE(w.remove_body(a).ok());
  EXPECT_FALSE(w.find(a).has_value());
  EXPECT_FALSE(w.remove_body(a).ok());  // stale: refused

  // The freed slot is taken again, under a new generation (the new body's id plus one).
  const BodyHandle b = w.add_body(hull, BodyState{}).value();
  EXPECT_EQ(b.index1, a.index1);
  EXPECT_NE(b.generation, a.generation);
  EXPECT_FALSE(w.find(a).has_value());
  EXPECT_EQ(w.body_id(*w.find(b)), 4);
  EXPECT_FALSE(w.find(BodyHandle{}).has_value());
  EXPECT_FALSE(w.find(BodyHandle{99, 1}).has_value());
}

TEST(WorldHandles, FollowTheirBodiesWhenEarlierOnesAreRemoved) {
  World w = make_world(builders::grid(6, true));
  std::vector<BodyHandle> handles;
  for (std::int32_t b = 0; b < w.body_count(); ++b) handles.push_back(w.handle(BodyId{b}));
  const BodyState state4 = w.state(BodyId{4});
  ASSERT_TRUE(w.remove_body(handles[1]).ok());
  ASSERT_TRUE(w.remove_body(handles[0]).ok());
  // Freed last, taken first: slot 0 then slot 1.
  EXPECT_EQ(w.add_body(builders::square({0.0, 0.0}), BodyState{}).value().index1, 1);
  EXPECT_EQ(w.add_body(builders::square({0.0, 0.0}), BodyState{}).value().index1, 2);
  const std::optional<BodyId> moved = w.find(handles[4]);
  ASSERT_TRUE(moved.has_value());
  EXPECT_EQ(moved->index, 2);
  EXPECT_TRUE(same_bits(w.state(*moved).position.x(), state4.position.x()));
  EXPECT_EQ(w.find_body_id(4)->index, 2);
  EXPECT_EQ(w.find_body_id(7)->index, 5);
  EXPECT_FALSE(w.find_body_id(1).has_value());
  ASSERT_TRUE(w.validate().ok()) << w.validate().error().message;
}

TEST(WorldContinueIds, AWorldMadeAgainContinuesTheSessionsIds) {
  World first = make_world(builders::free_bodies(Integrator::SymplecticEuler, 0.01, 2));
  const BodyHandle spawned = first.add_body(builders::square({0.0, 0.0}), BodyState{}).value();
  ASSERT_TRUE(first.add_spring(SpringDef{0, 2, {}, {}, 1.0, 0.0}).ok());
  // A reset makes the world again: the scene's bodies keep their ids, new ones continue.
  World again = make_world(builders::free_bodies(Integrator::SymplecticEuler, 0.01, 2));
  again.continue_ids(first.next_body_id(), first.next_spring_id());
  const BodyHandle next = again.add_body(builders::square({0.0, 0.0}), BodyState{}).value();
  EXPECT_EQ(again.body_id(*again.find(next)), 3);
  EXPECT_FALSE(again.find(spawned).has_value());  // same slot, another generation
  EXPECT_EQ(again.add_spring(SpringDef{0, 1, {}, {}, 1.0, 0.0}).value(), 1);
}

TEST(WorldReserve, ChangesWithinTheReserveKeepTheColumnsInPlace) {
  World w = make_world(builders::grid(10, true));
  w.reserve(64, 64);
  const double* x = w.x().data();
  for (int k = 0; k < 40; ++k) {
    const BodyHandle h =
        w.add_body(builders::polygon(5, 0.5, {0.0, 0.0}), BodyState{{1.0 * k, 0.0}, 0.1, {}, 0.0}).value();
    ASSERT_TRUE(w.add_spring(SpringDef{w.find(h)->index, 0, {}, {}, 2.0, 1.0}).ok());
    if (k % 3 == 0) {
      ASSERT_TRUE(w.remove_body(w.handle(BodyId{3})).ok());
    }
    w.step();
  }
  EXPECT_EQ(w.x().data(), x);  // no per-body column moved
  ASSERT_TRUE(w.validate().ok()) << w.validate().error().message;
}

TEST(WorldShapes, AnAddedBodyWithASceneBodysHullSharesItsShape) {
  WorldDef def = builders::grid(4, true);
  World w = make_world(def);
  ASSERT_EQ(w.shape_count(), 4);
  ASSERT_TRUE(w.add_body(def.bodies[2], BodyState{}).ok());
  EXPECT_EQ(w.shape_count(), 4);
  ASSERT_TRUE(w.add_body(builders::square({0.0, 0.0}), BodyState{}).ok());
  EXPECT_EQ(w.shape_count(), 5);
  ASSERT_TRUE(w.validate().ok()) << w.validate().error().message;
}

TEST(WorldShapes, ChurnWithEverNewHullsStaysBounded) {
  World w = make_world(builders::grid(20, true));
  for (int k = 0; k < 2000; ++k) {
    BodyDef hull = builders::polygon(6, 1.0, {0.0, 0.0});
    hull.hull[0].x() += 1e-6 * k;  // a hull no other body has
    const BodyHandle h = w.add_body(hull, BodyState{{0.0, 3.0}, 0.0, {}, 0.5}).value();
    if (k % 10 == 0) w.step();
    ASSERT_TRUE(w.remove_body(h).ok());
  }
  EXPECT_LE(w.shape_count(), 2 * w.body_count() + 17);
  ASSERT_TRUE(w.validate().ok()) << w.validate().error().message;
  // And the scene's bodies still step as a fresh world of the same definition does.
  World expected = oracle(builders::grid(20, true), states_of(w), w.step_index());
  step_both(w, expected, 10);
}

TEST(WorldStructure, RefusalsChangeNothing) {
  World w = make_world(busy_world());
  const std::size_t bytes = w.memory_bytes();
  const auto unchanged = [&] {
    EXPECT_EQ(w.body_count(), 5);
    EXPECT_EQ(w.spring_count(), 6);
    EXPECT_EQ(w.next_body_id(), 5);
    EXPECT_EQ(w.next_spring_id(), 6);
    EXPECT_TRUE(w.validate().ok());
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  BodyDef one_vertex;
  one_vertex.hull = {{0.0, 0.0}};
  one_vertex.masses = {1.0};
  EXPECT_FALSE(w.add_body(one_vertex, BodyState{}).ok());
  BodyDef coincident = builders::square({0.0, 0.0});
  for (Vec2& v : coincident.hull) v = {1.0, 1.0};
  const Result<BodyHandle> degenerate = w.add_body(coincident, BodyState{});
  ASSERT_FALSE(degenerate.ok());
  EXPECT_NE(degenerate.error().message.find("added body: all vertices coincide"), std::string::npos);
  EXPECT_FALSE(w.add_body(builders::square({0.0, 0.0}), BodyState{{nan, 0.0}, 0.0, {}, 0.0}).ok());
  EXPECT_FALSE(w.add_body(builders::square({0.0, 0.0}), BodyState{{}, 0.0, {}, nan}).ok());
  EXPECT_FALSE(w.add_spring(SpringDef{0, 5, {}, {}, 1.0, 0.0}).ok());   // no body 5
  EXPECT_FALSE(w.add_spring(SpringDef{0, 1, {}, {}, -1.0, 0.0}).ok());  // k < 0
  EXPECT_FALSE(w.remove_spring(99).ok());
  EXPECT_FALSE(w.remove_body(BodyHandle{}).ok());
  EXPECT_FALSE(w.remove_body(BodyHandle{1, 7}).ok());  // slot 0 holds generation 1
  unchanged();
  EXPECT_EQ(w.memory_bytes(), bytes);
}

}  // namespace
}  // namespace rbsim
