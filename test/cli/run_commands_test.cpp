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

// A fragment (rbsim/scene.hpp) the scripts spawn: two vertices, centre of mass at its origin.
constexpr const char* kBall =
    "<scene>\n  <rigidbodyvertex x=\"-0.1\" y=\"0\" m=\"1\"/>\n"
    "  <rigidbodyvertex x=\"0.1\" y=\"0\" m=\"1\"/>\n"
    "  <rigidbody p=\"0\" p=\"1\" vx=\"0.5\" vy=\"0\" omega=\"0\" r=\"0.05\"/>\n</scene>\n";

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
// by its id (the spawned body the next id, 5; a deleted body's rows end), the step of the change
// written with the world after it (as a recording read back holds it), and the scene's bodies step
// as the plain run's until the spawn's springs reach them.
TEST(RbsimRunCommands, SpawnAndDeleteChangeTheCsvRowsFromTheirStep) {
  const TempDir dir;
  write_text(dir / "ball.xml", kBall);
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
  ASSERT_EQ(b.size(), 1 + 10 * 5 + 10 * 6 + 11 * 5);
  for (std::size_t step = 0; step < 10; ++step) EXPECT_EQ(rows_at(a, step), rows_at(b, step)) << step;
  // Step 10: the scene's bodies as the plain run has them, and the ball at its spawn pose (its
  // centre of mass at x, theta as given, the fragment's velocity).
  const std::vector<std::string> at10(b.begin() + 1 + 10 * 5, b.begin() + 1 + 10 * 5 + 6);
  ASSERT_EQ(at10.size(), 6u);
  EXPECT_EQ(std::vector<std::string>(at10.begin(), at10.begin() + 5), rows_at(a, 10));
  EXPECT_TRUE(at10[5].starts_with("10,0.01,5,0.5,2,0.25,0.5,0,0,")) << at10[5];
  const auto body_of = [](const std::string& row) {
    const std::size_t c1 = row.find(',');
    const std::size_t c2 = row.find(',', c1 + 1);
    return row.substr(c2 + 1, row.find(',', c2 + 1) - c2 - 1);
  };
  for (std::size_t step = 10; step < 20; ++step) {
    for (std::size_t k = 0; k < 6; ++k) {
      const std::string& row = b[1 + 10 * 5 + (step - 10) * 6 + k];
      EXPECT_EQ(body_of(row), std::to_string(k)) << row;
      EXPECT_TRUE(row.starts_with(std::to_string(step) + ",")) << row;
    }
  }
  for (std::size_t step = 20; step <= 30; ++step) {
    const std::vector<std::string> ids = {"0", "1", "2", "3", "5"};
    for (std::size_t k = 0; k < 5; ++k) {
      EXPECT_EQ(body_of(b[1 + 10 * 5 + 10 * 6 + (step - 20) * 5 + k]), ids[k]) << step;
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

// A recording of a run whose bodies change holds an epoch per scene description: read back
// (`log export`), it gives the run's own CSVs byte for byte (the spawn's and the delete's steps
// with the world after them, each body by id); `render` draws it; and the session re-simulated
// from the recording's commands records the same bytes (`rbsim check`, tolerance 0).
TEST(RbsimRunCommands, ARecordingFollowsSpawnsAndDeletesAndReadsBackAsTheCsv) {
  const TempDir dir;
  write_text(dir / "ball.xml", kBall);
  write_text(dir / "c.yaml",
             "- {step: 10, spawn: {file: ball.xml, name: ball, x: [0.5, 2.0], theta: 0.25}}\n"
             "- {step: 20, delete: body_4}\n- {step: 20, spawn: {file: ball.xml, x: [-0.5, 2.0], theta: 0}}\n"
             "- {step: 25, reset_spawned: true}\n");
  const test::Outcome o = rbsim({"run", kScene, "--steps", "40", "--csv", (dir / "run.csv").string(),
                                 "--energy-csv", (dir / "run_energy.csv").string(), "--record",
                                 (dir / "r.mcap").string(), "--commands", (dir / "c.yaml").string()});
  ASSERT_EQ(o.exit_code, 0) << describe(o);
  const test::Outcome exported =
      rbsim({"log", "export", (dir / "r.mcap").string(), "--csv", (dir / "x.csv").string(), "--energy-csv",
             (dir / "x_energy.csv").string()});
  ASSERT_EQ(exported.exit_code, 0) << describe(exported);
  const std::string csv = read_text(dir / "run.csv");
  EXPECT_EQ(read_text(dir / "x.csv"), csv);
  EXPECT_EQ(read_text(dir / "x_energy.csv"), read_text(dir / "run_energy.csv"));
  // The epochs are really there: ids 5 and 6 appear, body 4 goes at 20, both spawned at 25.
  const std::vector<std::string> rows = lines_of(csv);
  EXPECT_EQ(rows.size(), 1 + 10 * 5 + 10 * 6 + 5 * 6 + 16 * 4);

  const test::Outcome frames =
      rbsim({"render", (dir / "r.mcap").string(), "--out", (dir / "frames").string(), "--fps", "200"});
  ASSERT_EQ(frames.exit_code, 0) << describe(frames);
  EXPECT_TRUE(fs::exists(dir / "frames" / "frame00007.png")) << describe(frames);

  const test::Outcome rerun = rbsim({"run", kScene, "--steps", "40", "--commands", (dir / "r.mcap").string(),
                                     "--record", (dir / "rerun.mcap").string()});
  ASSERT_EQ(rerun.exit_code, 0) << describe(rerun);
  const test::Outcome same = rbsim({"check", (dir / "rerun.mcap").string(), (dir / "r.mcap").string()});
  EXPECT_EQ(same.exit_code, 0) << describe(same);
}

}  // namespace
}  // namespace rbsim
