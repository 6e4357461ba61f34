// --ros-args (rbsim/ros_args.hpp): values typed as rcl types them, rcl's parameter files, and
// errors that name the file, the line and the parameter.
#include "rbsim/ros_args.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>

#include "control_test_util.hpp"

namespace rbsim::control {
namespace {

using V = ParameterValue;

V value(const char* text) {
  Result<V> v = parse_parameter_value(text);
  if (!v) throw std::runtime_error(v.error().message);
  return v.value();
}

TEST(ParseParameterValue, TypesScalarsAsRcl) {
  EXPECT_EQ(value("2"), V::of_integer(2));
  EXPECT_EQ(value("-17"), V::of_integer(-17));
  EXPECT_EQ(value("0x1f"), V::of_integer(31));  // strtoll base 0, as rcl
  EXPECT_EQ(value("2.0"), V::of_double(2.0));
  EXPECT_EQ(value("-3.7"), V::of_double(-3.7));
  EXPECT_EQ(value("1e-3"), V::of_double(1e-3));
  EXPECT_EQ(value("true"), V::of_bool(true));
  EXPECT_EQ(value("On"), V::of_bool(true));
  EXPECT_EQ(value("no"), V::of_bool(false));
  EXPECT_EQ(value("hello"), V::of_string("hello"));
  EXPECT_EQ(value("'2.0'"), V::of_string("2.0"));  // quoted: a string
  EXPECT_EQ(value("\"true\""), V::of_string("true"));
  EXPECT_EQ(value("!!str 5"), V::of_string("5"));
  EXPECT_TRUE(std::isinf(value("-.inf").double_value));
  EXPECT_LT(value("-.inf").double_value, 0.0);
  EXPECT_TRUE(std::isnan(value(".nan").double_value));
}

TEST(ParseParameterValue, SequencesAreArraysOfOneType) {
  V ints = value("[1, 2, 3]");
  EXPECT_EQ(ints.type, ParameterType::IntegerArray);
  EXPECT_EQ(ints.integer_array_value, (std::vector<std::int64_t>{1, 2, 3}));
  V doubles = value("[1.5, 2.5]");
  EXPECT_EQ(doubles.type, ParameterType::DoubleArray);
  EXPECT_EQ(doubles.double_array_value, (std::vector<double>{1.5, 2.5}));
  EXPECT_EQ(value("[a, 'b']").type, ParameterType::StringArray);
  EXPECT_FALSE(parse_parameter_value("[1, 2.0]").ok());  // mixed types, as rcl refuses
  EXPECT_FALSE(parse_parameter_value("{a: 1}").ok());
  EXPECT_FALSE(parse_parameter_value("").ok());
  EXPECT_FALSE(parse_parameter_value("[1, 2").ok());
}

TEST(NodeNameMatches, WildcardsAreWholeSegments) {
  EXPECT_TRUE(node_name_matches("/rbsim", "/rbsim"));
  EXPECT_TRUE(node_name_matches("rbsim", "/rbsim"));
  EXPECT_TRUE(node_name_matches("/**", "/rbsim"));
  EXPECT_TRUE(node_name_matches("/*", "/rbsim"));
  EXPECT_TRUE(node_name_matches("/**", "/a/b/rbsim"));
  EXPECT_TRUE(node_name_matches("/a/**/rbsim", "/a/rbsim"));
  EXPECT_TRUE(node_name_matches("/a/*", "/a/rbsim"));
  EXPECT_FALSE(node_name_matches("/*", "/a/rbsim"));
  EXPECT_FALSE(node_name_matches("/other", "/rbsim"));
  EXPECT_FALSE(node_name_matches("/rb*", "/rbsim"));
}

TEST(TakeRosArgs, CutsEverySectionUpToALoneDoubleDash) {
  std::vector<std::string> args = {"rbsim",  "node", "s.xml",      "--ros-args",    "-p",    "a:=1", "--",
                                   "--rate", "2",    "--ros-args", "--params-file", "f.yaml"};
  const std::vector<std::string> taken = take_ros_args(args);
  EXPECT_EQ(taken, (std::vector<std::string>{"-p", "a:=1", "--params-file", "f.yaml"}));
  EXPECT_EQ(args, (std::vector<std::string>{"rbsim", "node", "s.xml", "--rate", "2"}));
}

TEST(ParseRosArgs, ParamsInOrderWithTheirOrigins) {
  Result<std::vector<ParameterOverride>> o =
      parse_ros_args({"-p", "rate:=2.0", "--param", "forces.0.fy:=-3.7"}, "/rbsim");
  ASSERT_TRUE(o.ok()) << o.error().message;
  ASSERT_EQ(o.value().size(), 2u);
  EXPECT_EQ(o.value()[0].parameter.name, "rate");
  EXPECT_EQ(o.value()[0].parameter.value, V::of_double(2.0));
  EXPECT_EQ(o.value()[0].origin, "-p rate:=2.0");
  EXPECT_EQ(o.value()[1].parameter.value, V::of_double(-3.7));
}

TEST(ParseRosArgs, ErrorsNameTheArgument) {
  const auto message = [](std::vector<std::string> tokens) {
    Result<std::vector<ParameterOverride>> o = parse_ros_args(tokens, "/rbsim");
    return o.ok() ? std::string("(ok)") : o.error().message;
  };
  EXPECT_NE(message({"-r", "a:=b"}).find("'-r' is not supported"), std::string::npos);
  EXPECT_NE(message({"-p"}).find("-p needs a value"), std::string::npos);
  EXPECT_NE(message({"-p", "rate=2.0"}).find("expected NAME:=VALUE"), std::string::npos);
  EXPECT_NE(message({"-p", "rate:=[1, 2.0]"}).find("parameter 'rate'"), std::string::npos);
  EXPECT_NE(message({"--params-file", "/nonexistent/p.yaml"}).find("/nonexistent/p.yaml"), std::string::npos);
}

Result<std::vector<ParameterOverride>> file(const std::string& text, const std::string& node = "/rbsim") {
  return parse_params_yaml(text, "params.yaml", node);
}

TEST(ParseParamsYaml, ReadsTheNodesSectionsNestedMapsJoinedWithDots) {
  const std::string text = R"(/**:
  ros__parameters:
    use_sim_time: false
/rbsim:
  ros__parameters:
    rate: 2.0
    forces:
      0:
        fy: -3.7
    springs.1.k: 4.5
/other_node:
  ros__parameters:
    rate: 9.0
ns:
  rbsim:
    ros__parameters:
      publish_every: 3
)";
  Result<std::vector<ParameterOverride>> o = file(text);
  ASSERT_TRUE(o.ok()) << o.error().message;
  ASSERT_EQ(o.value().size(), 4u);
  EXPECT_EQ(o.value()[0].parameter.name, "use_sim_time");
  EXPECT_TRUE(o.value()[0].wildcard);
  EXPECT_EQ(o.value()[0].origin, "params.yaml:3");
  EXPECT_EQ(o.value()[1].parameter.name, "rate");
  EXPECT_FALSE(o.value()[1].wildcard);
  EXPECT_EQ(o.value()[2].parameter.name, "forces.0.fy");
  EXPECT_EQ(o.value()[2].parameter.value, V::of_double(-3.7));
  EXPECT_EQ(o.value()[2].origin, "params.yaml:9");
  EXPECT_EQ(o.value()[3].parameter.name, "springs.1.k");
  // /ns/rbsim is another node than /rbsim.
  Result<std::vector<ParameterOverride>> nested = file(text, "/ns/rbsim");
  ASSERT_TRUE(nested.ok());
  ASSERT_EQ(nested.value().size(), 2u);
  EXPECT_EQ(nested.value()[1].parameter.name, "publish_every");
}

TEST(ParseParamsYaml, ErrorsNameFileLineAndParameter) {
  const auto message = [](const std::string& text) {
    Result<std::vector<ParameterOverride>> o = file(text);
    return o.ok() ? std::string("(ok)") : o.error().message;
  };
  EXPECT_EQ(message("/rbsim:\n  ros__parameters:\n    rate: [1, 2.0]\n")
                .rfind("params.yaml:3: parameter 'rate'", 0),
            0u);
  EXPECT_EQ(message("/rbsim:\n  ros__parameters:\n    rate:\n")
                .rfind("params.yaml:3: parameter 'rate': no value", 0),
            0u);
  EXPECT_EQ(message("/rbsim:\n  ros__parameters:\n    rate: [1\n").rfind("params.yaml:", 0), 0u);
  EXPECT_NE(message("/rbsim:\n  ros__parameters:\n    rate: [1\n").find("not valid YAML"), std::string::npos);
  EXPECT_EQ(message("/rbsim:\n  ros__parameters: 5\n").rfind("params.yaml:2:", 0), 0u);
  EXPECT_EQ(message("- a\n- b\n").rfind("params.yaml:1: expected node names", 0), 0u);
  EXPECT_EQ(message("/rbsim:\n  rate: 2.0\n").rfind("params.yaml:2: expected a node name", 0), 0u);
}

// The whole path: a file on disk and -p, applied to a scene; a bad value names file, line and
// parameter.
TEST(ParseRosArgs, AFileAndParamsApplyInOrderAndBadValuesNameTheirLine) {
  const std::string path = ::testing::TempDir() + "rbsim_params_test.yaml";
  {
    std::ofstream out(path);
    out << "/rbsim:\n  ros__parameters:\n    forces.0.fy: -1.0\n    springs.0.k: 7\n";
  }
  Result<std::vector<ParameterOverride>> o =
      parse_ros_args({"-p", "forces.0.fy:=-2.0", "--params-file", path}, "/rbsim");
  ASSERT_TRUE(o.ok()) << o.error().message;
  Scene scene = test::control_scene();
  RunSettings settings;
  const Status st = apply_overrides(o.value(), scene, 100, settings);
  ASSERT_FALSE(st.ok());
  EXPECT_EQ(st.error().message.rfind(path + ":4: parameter 'springs.0.k': Wrong parameter type", 0), 0u)
      << st.error().message;
  {
    std::ofstream out(path);
    out << "/rbsim:\n  ros__parameters:\n    forces.0.fy: -1.0\n    springs.0.k: 7.0\n";
  }
  o = parse_ros_args({"--params-file", path, "-p", "forces.0.fy:=-2.0"}, "/rbsim");
  ASSERT_TRUE(o.ok());
  ASSERT_TRUE(apply_overrides(o.value(), scene, 100, settings).ok());
  EXPECT_EQ(scene.world.gravity[0].acceleration.y(), -2.0);  // -p came last
  EXPECT_EQ(scene.world.springs[0].stiffness, 7.0);
  std::remove(path.c_str());
}

}  // namespace
}  // namespace rbsim::control
