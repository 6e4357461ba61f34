// The parameter table (rbsim/parameters.hpp): declarations, values, every parameter's set and
// refuse paths, rclcpp's list semantics, and overrides applied to a scene.
#include "rbsim/parameters.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "control_test_util.hpp"

namespace rbsim::control {
namespace {

using V = ParameterValue;

std::vector<std::string> names(const ParameterTable& t) {
  std::vector<std::string> out;
  for (std::size_t i = 0; i < t.size(); ++i) out.push_back(t.descriptor(i).name);
  return out;
}

TEST(ParameterTable, DeclaresTheRunsParametersWithForcesInFileOrder) {
  const Scene scene = test::control_scene();
  const ParameterTable t(scene, 200, RunSettings{2.0, 3, false});
  std::vector<std::string> expected = {"scene",
                                       "dt",
                                       "integrator",
                                       "bodies",
                                       "springs",
                                       "steps",
                                       "rate",
                                       "publish_every",
                                       "paused",
                                       "use_sim_time",
                                       "service_configure_introspection",
                                       "forces.0.fx",
                                       "forces.0.fy",  // gravity
                                       "forces.1.beta",
                                       "forces.1.fx",
                                       "forces.1.fy",
                                       "forces.1.pointsperedge",  // wind
                                       "forces.2.fx",
                                       "forces.2.fy",  // gravity
                                       "springs.0.k",
                                       "springs.0.l0",
                                       "springs.1.k",
                                       "springs.1.l0"};
  // rclcpp's read-only node parameter, declared after use_sim_time.
  expected.insert(expected.begin() + 10, "start_type_description_service");
  EXPECT_EQ(names(t), expected);
  const auto value = [&](const char* name) { return t.value(*t.find(name)); };
  EXPECT_EQ(value("scene"), V::of_string("control.xml"));
  EXPECT_EQ(value("dt"), V::of_double(scene.world.dt));
  EXPECT_EQ(value("integrator"), V::of_string("symplectic-euler"));
  EXPECT_EQ(value("bodies"), V::of_integer(2));
  EXPECT_EQ(value("springs"), V::of_integer(2));
  EXPECT_EQ(value("steps"), V::of_integer(200));
  EXPECT_EQ(value("rate"), V::of_double(2.0));
  EXPECT_EQ(value("publish_every"), V::of_integer(3));
  EXPECT_EQ(value("paused"), V::of_bool(false));
  EXPECT_EQ(value("use_sim_time"), V::of_bool(false));
  EXPECT_EQ(value("service_configure_introspection"), V::of_string("disabled"));
  EXPECT_EQ(value("forces.0.fy"), V::of_double(scene.world.gravity[0].acceleration.y()));
  EXPECT_EQ(value("forces.1.beta"), V::of_double(scene.world.winds[0].beta));
  EXPECT_EQ(value("forces.1.pointsperedge"), V::of_integer(scene.world.winds[0].points_per_edge));
  EXPECT_EQ(value("forces.2.fx"), V::of_double(scene.world.gravity[1].acceleration.x()));
  EXPECT_EQ(value("springs.1.k"), V::of_double(scene.world.springs[1].stiffness));
  EXPECT_EQ(value("springs.0.l0"), V::of_double(scene.world.springs[0].rest_length));
  EXPECT_EQ(value("start_type_description_service"), V::of_bool(true));  // rclcpp's default
  const auto read_only = {
      "scene", "dt", "integrator", "bodies", "springs", "steps", "start_type_description_service"};
  for (const char* ro : read_only) EXPECT_TRUE(t.descriptor(*t.find(ro)).read_only) << ro;
  for (std::size_t i = 0; i < t.size(); ++i) {
    const std::string& name = t.descriptor(i).name;
    if (std::find(read_only.begin(), read_only.end(), name) == read_only.end()) {
      EXPECT_FALSE(t.descriptor(i).read_only) << name;
    }
  }
}

// One row per read-write parameter: a value it takes, one of the wrong type, one out of range.
struct Case {
  const char* name;
  V good;
  V wrong_type;
  std::optional<V> out_of_range;
};

std::vector<Case> cases() {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  return {
      {"rate", V::of_double(0.0), V::of_integer(2), V::of_double(-0.5)},
      {"publish_every", V::of_integer(1), V::of_double(2.0), V::of_integer(0)},
      {"paused", V::of_bool(true), V::of_integer(1), std::nullopt},
      {"use_sim_time", V::of_bool(false), V::of_string("false"), V::of_bool(true)},
      {"service_configure_introspection", V::of_string("contents"), V::of_bool(true), V::of_string("on")},
      {"forces.0.fx", V::of_double(-1e6), V::of_bool(true), V::of_double(nan)},
      {"forces.0.fy", V::of_double(3.7), V::of_integer(-3),
       V::of_double(-std::numeric_limits<double>::infinity())},
      {"forces.1.beta", V::of_double(0.0), V::of_integer(0), V::of_double(-1e-9)},
      {"forces.1.fx", V::of_double(5.0), V::of_string("5"), V::of_double(nan)},
      {"forces.1.fy", V::of_double(-5.0), V::of_integer(5),
       V::of_double(std::numeric_limits<double>::infinity())},
      {"forces.1.pointsperedge", V::of_integer(1'000'000), V::of_double(4.0), V::of_integer(1)},
      {"forces.2.fx", V::of_double(0.5), V::of_integer(1), V::of_double(nan)},
      {"forces.2.fy", V::of_double(0.5), V::of_bool(false), V::of_double(nan)},
      {"springs.0.k", V::of_double(0.0), V::of_integer(3), V::of_double(-2.0)},
      {"springs.0.l0", V::of_double(1.5), V::of_integer(1), V::of_double(-0.1)},
      {"springs.1.k", V::of_double(100.0), V::of_string("x"), V::of_double(nan)},
      {"springs.1.l0", V::of_double(0.0), V::of_bool(true), V::of_double(-1.0)},
  };
}

// After every change the table holds one springs.<id>.k|l0 pair per spring of the world, in its
// order, each pair's target the spring's index in the world and its name found at its place; the
// names that came and went are reported, and a spring kept keeps the value stored for it.
TEST(ParameterTable, FollowStructureKeepsOnePairPerSpringInTheWorldsOrder) {
  const Scene scene = test::control_scene();
  ParameterTable t(scene, 200, RunSettings{});
  World w = World::create(scene.world).value();
  const std::size_t springs_from = t.size() - 2 * static_cast<std::size_t>(w.spring_count());
  SpringDef extra = w.spring(SpringId{0});
  const auto expect_follows = [&](const char* what) {
    ASSERT_EQ(t.size(), springs_from + 2 * static_cast<std::size_t>(w.spring_count())) << what;
    for (std::int32_t s = 0; s < w.spring_count(); ++s) {
      const std::string p = "springs." + std::to_string(w.spring_id(SpringId{s})) + ".";
      for (std::size_t k = 0; k < 2; ++k) {
        const std::size_t i = springs_from + 2 * static_cast<std::size_t>(s) + k;
        EXPECT_EQ(t.descriptor(i).name, p + (k == 0 ? "k" : "l0")) << what;
        EXPECT_EQ(t.target(i).index, s) << what;
        EXPECT_EQ(t.find(t.descriptor(i).name), i) << what;
      }
    }
  };
  std::vector<Parameter> added;
  std::vector<std::string> removed;
  // Three springs join (ids 2, 3, 4 after the scene's two), one stored value set on id 2.
  for (int k = 0; k < 3; ++k) ASSERT_TRUE(w.add_spring(extra).ok());
  t.follow_structure(w, &added, &removed);
  expect_follows("after three added");
  EXPECT_EQ(added.size(), 6u);
  EXPECT_TRUE(removed.empty());
  t.store(*t.find("springs.2.k"), ParameterValue::of_double(42.0));
  // The scene's first and the second that joined go: the rest move up, keeping their values; one
  // more joins (id 5).
  added.clear();
  ASSERT_TRUE(w.remove_spring(w.spring_id(SpringId{0})).ok());
  ASSERT_TRUE(w.remove_spring(3).ok());
  ASSERT_TRUE(w.add_spring(extra).ok());
  t.follow_structure(w, &added, &removed);
  expect_follows("after removals");
  EXPECT_EQ(removed,
            (std::vector<std::string>{"springs.0.k", "springs.0.l0", "springs.3.k", "springs.3.l0"}));
  ASSERT_EQ(added.size(), 2u);
  EXPECT_EQ(added[0].name, "springs.5.k");
  EXPECT_FALSE(t.find("springs.0.k").has_value());
  EXPECT_EQ(t.value(*t.find("springs.2.k")), ParameterValue::of_double(42.0));
}

// follow() makes a copy made earlier equal to the table it was copied from, whatever changed since:
// values stored, springs added, the first removed, the table made again.
TEST(ParameterTable, FollowMakesAnEarlierCopyEqualToItsTable) {
  const Scene scene = test::control_scene();
  ParameterTable t(scene, 200, RunSettings{});
  ParameterTable published = t;
  World w = World::create(scene.world).value();
  const SpringDef extra = w.spring(SpringId{0});
  const auto expect_equal = [&](const char* what) {
    published.follow(t);
    ASSERT_EQ(names(published), names(t)) << what;
    for (std::size_t i = 0; i < t.size(); ++i) {
      EXPECT_EQ(published.value(i), t.value(i)) << what << ": " << t.descriptor(i).name;
      EXPECT_EQ(published.descriptor(i), t.descriptor(i)) << what;
      EXPECT_EQ(published.target(i).index, t.target(i).index) << what;
      EXPECT_EQ(published.find(t.descriptor(i).name), i) << what;
    }
  };
  expect_equal("unchanged");
  t.store(*t.find("rate"), V::of_double(3.0));
  t.store(*t.find("springs.1.l0"), V::of_double(0.25));
  expect_equal("two values stored");
  for (int k = 0; k < 3; ++k) ASSERT_TRUE(w.add_spring(extra).ok());
  t.follow_structure(w, nullptr, nullptr);
  expect_equal("three springs added");
  ASSERT_TRUE(w.remove_spring(w.spring_id(SpringId{0})).ok());
  ASSERT_TRUE(w.add_spring(extra).ok());
  t.follow_structure(w, nullptr, nullptr);
  t.store(*t.find("springs.3.k"), V::of_double(7.0));
  expect_equal("the first spring removed, one added, a value stored");
  EXPECT_FALSE(published.find("springs.0.k").has_value());
  t = ParameterTable(scene, 200, RunSettings{});
  expect_equal("a table made again");
  // A world loaded: another scene's table, as many parameters under other names (the wind first).
  std::string text = test::control_scene_text();
  const std::string gravity = R"(<rigidbodygravityforce fx="0.0" fy="-9.81"/>)";
  const std::size_t at = text.find(gravity);
  ASSERT_NE(at, std::string::npos);
  text.erase(at, gravity.size());
  text.insert(text.find("<rigidbodyspringforce"), gravity + "\n  ");
  const Scene other = test::scene_from(text);
  t = ParameterTable(other, 200, RunSettings{});
  ASSERT_EQ(t.size(), published.size());
  ASSERT_NE(names(t), names(published));
  expect_equal("another scene's table of as many parameters");
}

TEST(ParameterTableCheck, EveryReadWriteParameterTakesItsTypeInRangeAndRefusesTheRest) {
  const ParameterTable t(test::control_scene(), 200, RunSettings{});
  for (const Case& c : cases()) {
    SCOPED_TRACE(c.name);
    EXPECT_TRUE(t.check({c.name, c.good}).successful);
    const SetParametersResult type = t.check({c.name, c.wrong_type});
    EXPECT_FALSE(type.successful);
    EXPECT_NE(type.reason.find(std::string("{") + c.name + "}"), std::string::npos) << type.reason;
    EXPECT_NE(type.reason.find("Wrong parameter type"), std::string::npos) << type.reason;
    if (c.out_of_range) {
      const SetParametersResult range = t.check({c.name, *c.out_of_range});
      EXPECT_FALSE(range.successful);
      EXPECT_NE(range.reason.find(c.name), std::string::npos) << range.reason;
    }
  }
}

TEST(ParameterTableCheck, RefusesReadOnlyUnknownAndNotSet) {
  const ParameterTable t(test::control_scene(), 200, RunSettings{});
  for (const char* name :
       {"scene", "dt", "integrator", "bodies", "springs", "steps", "start_type_description_service"}) {
    const SetParametersResult r = t.check({name, t.value(*t.find(name))});  // even its own value
    EXPECT_FALSE(r.successful) << name;
    EXPECT_NE(r.reason.find("read-only"), std::string::npos) << r.reason;
    EXPECT_NE(r.reason.find(name), std::string::npos) << r.reason;
  }
  for (const char* name : {"forces.3.fx", "springs.2.k", "forces.1.fz", "gravity", ""}) {
    const SetParametersResult r = t.check({name, V::of_double(1.0)});
    EXPECT_FALSE(r.successful) << name;
    EXPECT_NE(r.reason.find("not declared"), std::string::npos) << r.reason;
  }
  EXPECT_FALSE(t.check({"rate", V{}}).successful);  // NOT_SET: no undeclaring
}

TEST(ParameterTableCheck, UseSimTimeTrueIsRefusedWithAReason) {
  const ParameterTable t(test::control_scene(), 200, RunSettings{});
  const SetParametersResult r = t.check({"use_sim_time", V::of_bool(true)});
  EXPECT_FALSE(r.successful);
  EXPECT_NE(r.reason.find("rbsim is the clock"), std::string::npos) << r.reason;
}

// The introspection demos' three words, and nothing else (the node switches on them).
TEST(ParameterTableCheck, ServiceIntrospectionTakesTheDemosWords) {
  const ParameterTable t(test::control_scene(), 200, RunSettings{});
  for (const char* word : {"disabled", "metadata", "contents"}) {
    EXPECT_TRUE(t.check({"service_configure_introspection", V::of_string(word)}).successful) << word;
  }
  for (const char* word : {"", "off", "Contents", "contents "}) {
    const SetParametersResult r = t.check({"service_configure_introspection", V::of_string(word)});
    EXPECT_FALSE(r.successful) << word;
    EXPECT_NE(r.reason.find("disabled, metadata or contents"), std::string::npos) << r.reason;
  }
  RunSettings settings;
  apply(t.target(*t.find("service_configure_introspection")), V::of_string("metadata"), settings);
  EXPECT_EQ(settings.service_introspection, msgs::IntrospectionState::Metadata);
}

TEST(ParameterTableCheck, AnIntegerForADoubleIsRefusedAsRclcppDoes) {
  const ParameterTable t(test::control_scene(), 200, RunSettings{});
  const SetParametersResult r = t.check({"rate", V::of_integer(2)});
  EXPECT_FALSE(r.successful);
  EXPECT_NE(
      r.reason.find("Wrong parameter type, parameter {rate} is of type {double}, setting it to {integer} "
                    "is not allowed."),
      std::string::npos)
      << r.reason;
}

TEST(ParameterTableList, FollowsRclcppPrefixAndDepthRules) {
  const ParameterTable t(test::control_scene(), 200, RunSettings{});
  const ListParametersResult all = t.list({}, kDepthRecursive);
  EXPECT_EQ(all.names, names(t));
  EXPECT_EQ(all.prefixes,
            (std::vector<std::string>{"forces.0", "forces.1", "forces.2", "springs.0", "springs.1"}));
  const ListParametersResult top = t.list({}, 1);  // names without a '.'
  for (const std::string& n : top.names) EXPECT_EQ(n.find('.'), std::string::npos) << n;
  EXPECT_EQ(top.names.size(), 12u);  // the six read-only, rate, publish_every, paused, use_sim_time,
                                     // start_type_description_service, introspection
  const ListParametersResult wind = t.list({"forces.1"}, kDepthRecursive);
  EXPECT_EQ(wind.names, (std::vector<std::string>{"forces.1.beta", "forces.1.fx", "forces.1.fy",
                                                  "forces.1.pointsperedge"}));
  EXPECT_EQ(t.list({"forces"}, 1).names.size(), 0u);  // forces.<i>.<a>: <i>.<a> has one '.'
  EXPECT_EQ(t.list({"forces"}, 2).names.size(), 8u);
  EXPECT_EQ(t.list({"forces.1"}, 1).names.size(), 4u);
  EXPECT_EQ(t.list({"rate"}, kDepthRecursive).names, std::vector<std::string>{"rate"});
}

TEST(ApplyOverrides, EditsTheSceneAndSettingsAsOneBatch) {
  Scene scene = test::control_scene();
  RunSettings settings;
  const std::vector<ParameterOverride> overrides = {
      {{"forces.2.fy", V::of_double(-2.0)}, "-p", false},
      {{"rate", V::of_double(4.0)}, "-p", false},
      {{"forces.2.fy", V::of_double(-3.0)}, "f.yaml:3", false},  // the last wins
      {{"springs.1.l0", V::of_double(2.5)}, "f.yaml:4", false},
      {{"forces.1.pointsperedge", V::of_integer(9)}, "f.yaml:5", false},
      {{"paused", V::of_bool(true)}, "f.yaml:6", false},
  };
  ASSERT_TRUE(apply_overrides(overrides, scene, 200, settings).ok());
  EXPECT_EQ(scene.world.gravity[1].acceleration.y(), -3.0);
  EXPECT_EQ(scene.world.springs[1].rest_length, 2.5);
  EXPECT_EQ(scene.world.winds[0].points_per_edge, 9);
  EXPECT_EQ(settings.rate, 4.0);
  EXPECT_TRUE(settings.paused);
}

// rclcpp's start_type_description_service is read-only and takes its value from an override
// (-p start_type_description_service:=false); the scene's read-only parameters take none.
TEST(ApplyOverrides, StartTypeDescriptionServiceIsGivenByAnOverrideOnly) {
  Scene scene = test::control_scene();
  RunSettings settings;
  EXPECT_TRUE(settings.start_type_description_service);
  ASSERT_TRUE(apply_overrides({{{"start_type_description_service", V::of_bool(false)}, "-p", false}}, scene,
                              200, settings)
                  .ok());
  EXPECT_FALSE(settings.start_type_description_service);
  const ParameterTable t(scene, 200, settings);
  EXPECT_EQ(t.value(*t.find("start_type_description_service")), V::of_bool(false));
  const Status wrong_type = apply_overrides(
      {{{"start_type_description_service", V::of_integer(0)}, "-p", false}}, scene, 200, settings);
  ASSERT_FALSE(wrong_type.ok());
  EXPECT_NE(wrong_type.error().message.find("Wrong parameter type"), std::string::npos);
  const Status dt = apply_overrides({{{"dt", V::of_double(0.5)}, "-p", false}}, scene, 200, settings);
  ASSERT_FALSE(dt.ok());
  EXPECT_NE(dt.error().message.find("read-only"), std::string::npos);
}

TEST(ApplyOverrides, TheFirstBadOneNamesOriginAndParameterAndNothingChanges) {
  Scene scene = test::control_scene();
  const WorldDef before = scene.world;
  RunSettings settings;
  const std::vector<ParameterOverride> overrides = {
      {{"forces.0.fy", V::of_double(-2.0)}, "-p forces.0.fy:=-2.0", false},
      {{"springs.0.k", V::of_integer(3)}, "params.yaml:7", false},
  };
  const Status st = apply_overrides(overrides, scene, 200, settings);
  ASSERT_FALSE(st.ok());
  EXPECT_EQ(st.error().message.rfind("params.yaml:7: parameter 'springs.0.k': ", 0), 0u)
      << st.error().message;
  EXPECT_EQ(scene.world.gravity[0].acceleration.y(), before.gravity[0].acceleration.y());
}

TEST(ApplyOverrides, UnknownNamesAreErrorsUnlessFromAWildcardKey) {
  Scene scene = test::control_scene();
  RunSettings settings;
  std::vector<std::string> warnings;
  ASSERT_TRUE(apply_overrides({{{"qos_overrides.x", V::of_integer(1)}, "f.yaml:2", true}}, scene, 200,
                              settings, &warnings)
                  .ok());
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("f.yaml:2"), std::string::npos);
  EXPECT_NE(warnings[0].find("qos_overrides.x"), std::string::npos);
  const Status st = apply_overrides({{{"qos_overrides.x", V::of_integer(1)}, "f.yaml:2", false}}, scene, 200,
                                    settings, &warnings);
  EXPECT_FALSE(st.ok());
}

TEST(ParameterValueToString, ReadsAsTyped) {
  EXPECT_EQ(to_string(V::of_double(0.1)), "0.1");
  EXPECT_EQ(to_string(V::of_integer(-7)), "-7");
  EXPECT_EQ(to_string(V::of_bool(true)), "true");
  EXPECT_EQ(to_string(V::of_string("a")), "'a'");
  V array;
  array.type = ParameterType::IntegerArray;
  array.integer_array_value = {1, 2};
  EXPECT_EQ(to_string(array), "[1, 2]");
}

}  // namespace
}  // namespace rbsim::control
