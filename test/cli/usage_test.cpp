// The rbsim command line's usage errors: every one exits 2 with one line that starts with the
// command ("rbsim check: error: ..."), unknown commands are named, and `rbsim help` works.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <ostream>
#include <string>
#include <vector>

#include "rbsim/subprocess.hpp"

namespace rbsim {
namespace {

using test::rbsim;

struct UsageCase {
  std::vector<std::string> args;
  std::string first_line;  // how stderr must start
  std::string mentions;    // and something it must say
};

void PrintTo(const UsageCase& c, std::ostream* os) {
  *os << "rbsim";
  for (const std::string& a : c.args) *os << ' ' << a;
}

class Usage : public ::testing::TestWithParam<UsageCase> {};

TEST_P(Usage, ExitsTwoWithTheCommandAndTheProblem) {
  const UsageCase& c = GetParam();
  const test::Outcome o = rbsim(c.args);
  EXPECT_EQ(o.exit_code, 2) << o;
  ASSERT_FALSE(o.err_lines().empty()) << o;
  EXPECT_EQ(o.err_lines()[0].rfind(c.first_line, 0), 0u) << o;
  EXPECT_NE(o.err.find(c.mentions), std::string::npos) << o;
  EXPECT_LT(o.err.size(), 400u) << "a usage error is a line or two: " << o;
}

INSTANTIATE_TEST_SUITE_P(
    Cli, Usage,
    ::testing::Values(
        UsageCase{{}, "rbsim: error: no command given", "run, grade"},
        UsageCase{{"frobnicate"}, "rbsim: error: unknown command 'frobnicate'", "run, grade"},
        UsageCase{{"help", "frobnicate"}, "rbsim: error: unknown command 'frobnicate'", "--help"},
        UsageCase{{"log", "frob"},
                  "rbsim log: error: unknown command 'frob'",
                  "info, doctor, recover, export, cat"},
        UsageCase{{"check", "a.mcap", "b.mcap", "--atol", "abc"}, "rbsim check: error:", "--atol"},
        UsageCase{{"check", "x", "y", "z"}, "rbsim check: error:", "rbsim check --help"},
        UsageCase{{"run", "scene.xml", "--steps", "-1"}, "rbsim run: error:", "--steps"},
        UsageCase{{"run", "scene.xml", "--no-such-flag"}, "rbsim run: error:", "--no-such-flag"},
        UsageCase{{"log", "info"}, "rbsim log info: error:", "file"},
        // Options of an output that was not asked for would be silently ignored.
        UsageCase{{"run", "scene.xml", "--fps", "30"}, "rbsim run: error: --fps requires --frames", "--fps"},
        UsageCase{{"run", "scene.xml", "--record-every", "3"},
                  "rbsim run: error: --record-every requires --record",
                  "--record"},
        // Topic names follow ROS 2's rules.
        UsageCase{{"run", "scene.xml", "--record", "x.mcap", "--namespace", "a b"},
                  "rbsim run: error: --namespace",
                  "is not a ROS 2 namespace"},
        UsageCase{{"node", "scene.xml", "--namespace", "1robot"},
                  "rbsim node: error: --namespace",
                  "must not start with a digit"},
        UsageCase{{"record", "x.mcap", "--namespace", "a//b"}, "rbsim record: error: --namespace", "//"},
        // --duration is simulated time everywhere; a recorder's wall-clock limit has its own name.
        UsageCase{
            {"record", "x.mcap", "--duration", "3"}, "rbsim record: error: --duration", "--wall-duration"},
        // --topics: an unknown name is named, with the valid ones; checked in the chosen namespace.
        UsageCase{{"run", "scene.xml", "--record", "x.mcap", "--topics", "body_states,tfs"},
                  "rbsim run: error: --topics",
                  "unknown topic \"tfs\" (topics: /clock, /rbsim/body_states, /rbsim/energy"},
        UsageCase{{"run", "scene.xml", "--record", "x.mcap", "--namespace", "a", "--topics", "/rbsim/energy"},
                  "rbsim run: error: --topics",
                  "unknown topic \"/rbsim/energy\""},
        UsageCase{{"run", "scene.xml", "--topics", "tf"},
                  "rbsim run: error: --topics requires --record",
                  "--record"},
        UsageCase{{"node", "scene.xml", "--topics", "poses,bogus"},
                  "rbsim node: error: --topics",
                  "unknown topic \"bogus\""},
        UsageCase{{"node", "scene.xml", "--topics", ","}, "rbsim node: error: --topics", "no topic given"},
        // --spawnables names a folder that exists.
        UsageCase{{"node", "scene.xml", "--spawnables", "/no/such/folder"},
                  "rbsim node: error: --spawnables",
                  "no folder \"/no/such/folder\""},
        UsageCase{{"log", "cat"}, "rbsim log cat: error:", "file"},
        UsageCase{{"log", "cat", "x.mcap", "--start", "-1"}, "rbsim log cat: error:", "--start"}));

// rbsim node --ros-args: a bad parameter is a usage error naming where it came from and the
// parameter, before any DDS is started.
TEST(NodeRosArgs, BadParametersAreUsageErrorsNamingOriginAndParameter) {
  const std::string scene = std::string(RBSIM_TEST_DATA_DIR) + "/fosssim/scenes/gravitytests/test00sym.xml";
  const std::string yaml = ::testing::TempDir() + "rbsim_usage_params.yaml";
  {
    std::ofstream out(yaml);
    out << "/rbsim:\n  ros__parameters:\n    forces.0.fx: 1.0\n    forces.0.fy: abc\n";
  }
  struct Case {
    std::vector<std::string> args;
    std::string mentions;
  };
  for (const Case& c : std::vector<Case>{
           {{"-p", "rate:=2"}, "-p rate:=2: parameter 'rate': Wrong parameter type"},
           {{"-p", "forces.1.fx:=1.0"}, "parameter 'forces.1.fx': parameter 'forces.1.fx' is not declared"},
           {{"-p", "use_sim_time:=true"}, "rbsim is the clock"},
           {{"-p", "dt:=0.1"}, "read-only"},
           {{"--params-file", yaml}, yaml + ":4: parameter 'forces.0.fy'"},
           {{"-r", "a:=b"}, "'-r' is not supported"},
       }) {
    std::vector<std::string> args = {"node", scene, "--domain", "0", "--ros-args"};
    args.insert(args.end(), c.args.begin(), c.args.end());
    const test::Outcome o = rbsim(args);
    EXPECT_EQ(o.exit_code, 2) << o;
    ASSERT_FALSE(o.err_lines().empty()) << o;
    EXPECT_EQ(o.err_lines()[0].rfind("rbsim node: error: ", 0), 0u) << o;
    EXPECT_NE(o.err.find(c.mentions), std::string::npos) << o;
  }
  std::remove(yaml.c_str());
  // Only rbsim node takes ROS arguments.
  const test::Outcome run = rbsim({"run", scene, "--ros-args", "-p", "rate:=2.0"});
  EXPECT_EQ(run.exit_code, 2) << run;
  EXPECT_NE(run.err.find("--ros-args"), std::string::npos) << run;
}

TEST(Help, HelpCommandShowsTheCommandsHelp) {
  const test::Outcome o = rbsim({"help", "log", "recover"});
  EXPECT_EQ(o.exit_code, 0) << o;
  EXPECT_NE(o.out.find("Usage: rbsim log recover"), std::string::npos) << o;
  EXPECT_NE(o.out.find("Exit status"), std::string::npos) << o;
}

// Counts read as English: "1 body, 0 springs, 1 step".
TEST(Summary, CountsAgreeWithTheirNouns) {
  const test::Outcome o =
      rbsim({"run", std::string(RBSIM_TEST_DATA_DIR) + "/fosssim/scenes/gravitytests/test00sym.xml",
             "--steps", "1"});
  EXPECT_EQ(o.exit_code, 0) << o;
  EXPECT_NE(o.err.find(": 1 body, 0 springs, 1 step ("), std::string::npos) << o;
}

// Every command states its exit codes in its --help.
TEST(Help, EveryCommandStatesItsExitStatus) {
  for (const std::vector<std::string>& command : std::vector<std::vector<std::string>>{{},
                                                                                       {"run"},
                                                                                       {"grade"},
                                                                                       {"render"},
                                                                                       {"plot"},
                                                                                       {"node"},
                                                                                       {"record"},
                                                                                       {"replay"},
                                                                                       {"check"},
                                                                                       {"log", "info"},
                                                                                       {"log", "doctor"},
                                                                                       {"log", "recover"},
                                                                                       {"log", "export"},
                                                                                       {"log", "cat"}}) {
    std::vector<std::string> args = command;
    args.push_back("--help");
    const test::Outcome o = rbsim(args);
    EXPECT_EQ(o.exit_code, 0) << o;
    EXPECT_NE(o.out.find("Exit status"), std::string::npos)
        << "rbsim " << testing::PrintToString(command) << o;
  }
}

// rbsim node --spawnables: its --help says what the folder is for and its rules; a file where a
// folder belongs is a usage error too.
TEST(Help, NodeDescribesSpawnables) {
  const test::Outcome o = rbsim({"node", "--help"});
  EXPECT_EQ(o.exit_code, 0) << o;
  for (const char* text :
       {"--spawnables", "spawn_entity", "spawn_entities", "get_spawnables", "no '..'", "no symbolic links"}) {
    EXPECT_NE(o.out.find(text), std::string::npos) << text << o;
  }
  const std::string scene = std::string(RBSIM_TEST_DATA_DIR) + "/fosssim/scenes/gravitytests/test00sym.xml";
  const test::Outcome file = rbsim({"node", scene, "--domain", "0", "--spawnables", scene});
  EXPECT_EQ(file.exit_code, 2) << file;
  ASSERT_FALSE(file.err_lines().empty()) << file;
  EXPECT_EQ(file.err_lines()[0], "rbsim node: error: --spawnables: \"" + scene + "\" is not a folder")
      << file;
}

// rbsim replay's player: every flag and the services in its --help; a bad value is a usage error.
TEST(Help, ReplayDescribesThePlayer) {
  const test::Outcome o = rbsim({"replay", "--help"});
  EXPECT_EQ(o.exit_code, 0) << o;
  for (const char* text : {"--start-paused", "--playback-duration", "--playback-until", "--delay",
                           "pause, resume", "toggle_paused", "is_paused", "get_rate", "set_rate", "seek",
                           "play_next", "burst", "rosbag2_interfaces/srv", "progress line"}) {
    EXPECT_NE(o.out.find(text), std::string::npos) << text << o;
  }
  for (const std::vector<std::string>& bad :
       std::vector<std::vector<std::string>>{{"--playback-duration", "-1"},
                                             {"--playback-until", "x"},
                                             {"--delay", "-0.5"},
                                             {"--playback-duration"}}) {
    std::vector<std::string> args = {"replay", "in.mcap"};
    args.insert(args.end(), bad.begin(), bad.end());
    const test::Outcome r = rbsim(args);
    EXPECT_EQ(r.exit_code, 2) << testing::PrintToString(bad) << r;
  }
}

}  // namespace
}  // namespace rbsim

namespace rbsim {
namespace {

// rbsim security: a keystore once (never over an existing one), enclaves with their permissions,
// bad enclave names as usage errors.
TEST(SecurityCli, CreateKeystoreAndEnclaveAsRos2SecurityDoes) {
  test::TempDir dir;
  const std::string ks = (dir / "ks").string();
  test::Outcome o = test::rbsim({"security", "create-keystore", ks});
  ASSERT_EQ(o.exit_code, 0) << o;
  o = test::rbsim({"security", "create-keystore", ks});
  EXPECT_EQ(o.exit_code, 1) << o;
  EXPECT_NE(o.err.find("already a keystore"), std::string::npos) << o;
  o = test::rbsim(
      {"security", "create-enclave", ks, "/arm", "--namespace", "robots", "--topics", "scene,markers"});
  ASSERT_EQ(o.exit_code, 0) << o;
  const std::string permissions = test::read_text(dir / "ks/enclaves/arm/permissions.xml");
  EXPECT_NE(permissions.find("<topic>rt/robots/markers</topic>"), std::string::npos) << permissions;
  EXPECT_EQ(permissions.find("rt/robots/*"), std::string::npos) << permissions;
  o = test::rbsim({"security", "create-enclave", ks, "arm"});
  EXPECT_EQ(o.exit_code, 2) << o;
  EXPECT_NE(o.err.find("enclave \"arm\": an absolute path"), std::string::npos) << o;
  o = test::rbsim({"security", "create-enclave", (dir / "none").string(), "/arm"});
  EXPECT_EQ(o.exit_code, 1) << o;
  o = test::rbsim({"security", "--help"});
  EXPECT_EQ(o.exit_code, 0) << o;
  EXPECT_NE(o.out.find("ROS_SECURITY_ENABLE"), std::string::npos) << o;
}

}  // namespace
}  // namespace rbsim
