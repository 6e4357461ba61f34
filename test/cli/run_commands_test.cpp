// `rbsim run --commands FILE`: a script of commands applied at step boundaries, as a user runs it.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "rbsim/subprocess.hpp"

namespace rbsim {
namespace {

namespace fs = std::filesystem;
using test::lines_of;
using test::rbsim;
using test::read_text;
using test::TempDir;
using test::write_text;

const std::string kScene = std::string(RBSIM_TEST_DATA_DIR) + "/../../scenes/chain.xml";  // 5 bodies, dt 1 ms

std::string describe(const test::Outcome& o) {
  return "exit " + std::to_string(o.exit_code) + "\nstdout: " + o.out + "\nstderr: " + o.err;
}

// The CSV rows of one step (5 bodies a step, after the header).
std::vector<std::string> rows_at(const std::vector<std::string>& csv, std::size_t step) {
  return {csv.begin() + 1 + 5 * step, csv.begin() + 1 + 5 * (step + 1)};
}

TEST(RbsimRunCommands, EachCommandActsFromTheStepAfterItsBoundary) {
  const TempDir dir;
  write_text(dir / "c.yaml",
             "- {step: 20, set: {forces.0.fy: -3.7}}\n"
             "- {t: 0.05, impulse: {body: 2, j: [0.5, 2.0], p: [0.1, 0.0]}}\n"
             "- {step: 60, pause: true}\n- {step: 60, steps: 3}\n- {step: 63, resume: true}\n");
  const test::Outcome plain = rbsim({"run", kScene, "--steps", "100", "--csv", (dir / "plain.csv").string()});
  ASSERT_EQ(plain.exit_code, 0) << describe(plain);
  const test::Outcome only_set = rbsim({"run", kScene, "--steps", "100", "--csv", (dir / "set.csv").string(),
                                        "--commands", (dir / "c.yaml").string()});
  ASSERT_EQ(only_set.exit_code, 0) << describe(only_set);
  const std::vector<std::string> a = lines_of(read_text(dir / "plain.csv"));
  const std::vector<std::string> b = lines_of(read_text(dir / "set.csv"));
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t step = 0; step <= 20; ++step) EXPECT_EQ(rows_at(a, step), rows_at(b, step)) << step;
  EXPECT_NE(rows_at(a, 21), rows_at(b, 21));
  // The same script again: the same bytes (pauses change wall time only).
  const test::Outcome again = rbsim({"run", kScene, "--steps", "100", "--csv", (dir / "again.csv").string(),
                                     "--commands", (dir / "c.yaml").string()});
  ASSERT_EQ(again.exit_code, 0) << describe(again);
  EXPECT_EQ(read_text(dir / "again.csv"), read_text(dir / "set.csv"));
}

// t: SECONDS names the first step at or after it: the same run as the step form.
TEST(RbsimRunCommands, TimeAndStepFormsGiveTheSameRun) {
  const TempDir dir;
  write_text(dir / "steps.yaml",
             "- {step: 50, set: {forces.0.fy: -3.7}}\n- {step: 75, impulse: {body: 1, j: [1, 0]}}\n");
  write_text(dir / "times.yaml",
             "- {t: 0.05, set: {forces.0.fy: -3.7}}\n- {t: 0.0745, impulse: {body: 1, j: [1, 0]}}\n");
  for (const char* form : {"steps", "times"}) {
    const test::Outcome o =
        rbsim({"run", kScene, "--steps", "100", "--csv", (dir / (std::string(form) + ".csv")).string(),
               "--commands", (dir / (std::string(form) + ".yaml")).string()});
    ASSERT_EQ(o.exit_code, 0) << describe(o);
  }
  EXPECT_EQ(read_text(dir / "steps.csv"), read_text(dir / "times.csv"));
}

TEST(RbsimRunCommands, ABadScriptIsAUsageErrorBeforeAnyOutput) {
  const TempDir dir;
  write_text(dir / "c.yaml",
             "- {step: 20, set: {forces.0.fy: -3.7}}\n- {step: 30, impulse: {body: 9, j: [0, 1]}}\n");
  const test::Outcome o = rbsim({"run", kScene, "--steps", "100", "--csv", (dir / "out.csv").string(),
                                 "--commands", (dir / "c.yaml").string()});
  EXPECT_EQ(o.exit_code, 2) << describe(o);
  EXPECT_NE(o.err.find("c.yaml:2: impulse.body: must be a body index in [0, 5)"), std::string::npos)
      << describe(o);
  EXPECT_FALSE(fs::exists(dir / "out.csv"));
  const test::Outcome missing = rbsim({"run", kScene, "--commands", (dir / "none.yaml").string()});
  EXPECT_EQ(missing.exit_code, 1) << describe(missing);
  EXPECT_NE(missing.err.find("none.yaml"), std::string::npos) << describe(missing);
  // An output may not overwrite the script.
  write_text(dir / "ok.yaml", "- {step: 1, resume: true}\n");
  const test::Outcome clash = rbsim({"run", kScene, "--csv", (dir / "ok.yaml").string(), "--overwrite",
                                     "--commands", (dir / "ok.yaml").string()});
  EXPECT_NE(clash.exit_code, 0) << describe(clash);
  EXPECT_EQ(read_text(dir / "ok.yaml"), "- {step: 1, resume: true}\n");
}

// A script's spawn and delete: the CSV rows hold the bodies the world has at each step, each named
// by its id (the spawned body the next id, 5; a deleted body's rows end), and the scene's bodies
// step as the plain run's until the spawn's springs reach them.
TEST(RbsimRunCommands, SpawnAndDeleteChangeTheCsvRowsFromTheNextStep) {
  const TempDir dir;
  write_text(dir / "ball.xml",
             "<scene>\n  <rigidbodyvertex x=\"-0.1\" y=\"0\" m=\"1\"/>\n"
             "  <rigidbodyvertex x=\"0.1\" y=\"0\" m=\"1\"/>\n"
             "  <rigidbody p=\"0\" p=\"1\" vx=\"0.5\" vy=\"0\" omega=\"0\" r=\"0.05\"/>\n</scene>\n");
  write_text(dir / "c.yaml",
             "- {step: 10, spawn: {file: ball.xml, name: ball, x: [0.5, 2.0], theta: 0.25}}\n"
             "- {step: 20, delete: body_4}\n");
  const test::Outcome plain = rbsim({"run", kScene, "--steps", "30", "--csv", (dir / "plain.csv").string()});
  ASSERT_EQ(plain.exit_code, 0) << describe(plain);
  const test::Outcome o = rbsim({"run", kScene, "--steps", "30", "--csv", (dir / "out.csv").string(),
                                 "--commands", (dir / "c.yaml").string()});
  ASSERT_EQ(o.exit_code, 0) << describe(o);
  const std::vector<std::string> a = lines_of(read_text(dir / "plain.csv"));
  const std::vector<std::string> b = lines_of(read_text(dir / "out.csv"));
  ASSERT_EQ(b.size(), 1 + 11 * 5 + 10 * 6 + 10 * 5);
  for (std::size_t step = 0; step <= 10; ++step) EXPECT_EQ(rows_at(a, step), rows_at(b, step)) << step;
  const auto body_of = [](const std::string& row) {
    const std::size_t c1 = row.find(',');
    const std::size_t c2 = row.find(',', c1 + 1);
    return row.substr(c2 + 1, row.find(',', c2 + 1) - c2 - 1);
  };
  for (std::size_t step = 11; step <= 20; ++step) {
    for (std::size_t k = 0; k < 6; ++k) {
      const std::string& row = b[1 + 11 * 5 + (step - 11) * 6 + k];
      EXPECT_EQ(body_of(row), std::to_string(k)) << row;
      EXPECT_TRUE(row.starts_with(std::to_string(step) + ",")) << row;
    }
  }
  for (std::size_t step = 21; step <= 30; ++step) {
    const std::vector<std::string> ids = {"0", "1", "2", "3", "5"};
    for (std::size_t k = 0; k < 5; ++k) {
      EXPECT_EQ(body_of(b[1 + 11 * 5 + 10 * 6 + (step - 21) * 5 + k]), ids[k]) << step;
    }
  }
  // An output that cannot follow a changed world (the FOSSSim binary): the run is refused,
  // naming the command, and writes nothing.
  const test::Outcome refused = rbsim({"run", kScene, "--steps", "30", "--fosssim-out",
                                       (dir / "out.bin").string(), "--commands", (dir / "c.yaml").string()});
  EXPECT_NE(refused.exit_code, 0) << describe(refused);
  EXPECT_NE(refused.err.find("spawn_entity"), std::string::npos) << describe(refused);
  EXPECT_FALSE(fs::exists(dir / "out.bin"));
}

}  // namespace
}  // namespace rbsim
