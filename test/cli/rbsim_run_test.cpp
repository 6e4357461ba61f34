// `rbsim run` as a user runs it: options, output files, determinism and errors.
#include <gtest/gtest.h>

#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "bad_scenes.hpp"
#include "rbsim/scene.hpp"
#include "rbsim/subprocess.hpp"

namespace rbsim {
namespace {

namespace fs = std::filesystem;
using test::lines_of;
using test::rbsim;
using test::read_text;
using test::split;
using test::TempDir;

const std::string kData = RBSIM_TEST_DATA_DIR;
const std::string kScenes = kData + "/fosssim/scenes";
const std::string kCsvHeader = "step,t,body,x,y,theta,vx,vy,omega,px,py,L_point,L_spin,T_point,T_spin";
const std::string kEnergyHeader = "step,t,U,T_point,T_spin,T,E,U_gravity,U_spring,px,py,L";

// Describes a finished process for failure messages.
std::string describe(const test::Outcome& o) {
  return "exit " + std::to_string(o.exit_code) + (o.timed_out ? " (timed out)" : "") +
         (o.signal ? " signal " + std::to_string(o.signal) : "") + "\nstdout: " + o.out +
         "\nstderr: " + o.err;
}

double parse_double(const std::string& s) {
  double v = 0.0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || end != s.data() + s.size()) ADD_FAILURE() << "not a number: \"" << s << "\"";
  return v;
}

bool same_bits(double a, double b) {
  return std::memcmp(&a, &b, sizeof a) == 0;
}

World world_of(const std::string& scene_path) {
  Result<Scene> s = load_scene(scene_path);
  if (!s) throw std::runtime_error(s.error().message);
  Result<World> w = World::create(s->world);
  if (!w) throw std::runtime_error(w.error().message);
  return std::move(w.value());
}

struct Outputs {
  fs::path csv, energy, fosssim;
};
Outputs outputs_in(const TempDir& dir, const std::string& tag = "") {
  return {dir / ("bodies" + tag + ".csv"), dir / ("energy" + tag + ".csv"), dir / ("ref" + tag + ".bin")};
}
std::vector<std::string> output_args(const Outputs& o) {
  return {"--csv", o.csv.string(), "--energy-csv", o.energy.string(), "--fosssim-out", o.fosssim.string()};
}

// ---------------------------------------------------------------------------------------------
TEST(RbsimRun, HelpExitsZeroAndMentionsEveryOption) {
  const test::Outcome o = rbsim({"run", "--help"});
  ASSERT_EQ(o.exit_code, 0) << describe(o);
  for (const char* option : {"--steps", "--duration", "--csv", "--energy-csv", "--fosssim-out", "--progress",
                             "--quiet", "--allow-nonfinite", "--commands", "--help"}) {
    EXPECT_NE(o.out.find(option), std::string::npos) << option << " not in help:\n" << o.out;
  }
  EXPECT_NE(o.out.find(kCsvHeader), std::string::npos) << "help should document the CSV columns";
  EXPECT_NE(o.out.find(kEnergyHeader), std::string::npos) << "help should document the energy CSV columns";
  EXPECT_NE(o.out.find("Exit status"), std::string::npos);

  const test::Outcome top = rbsim({"--help"});
  ASSERT_EQ(top.exit_code, 0) << describe(top);
  EXPECT_NE(top.out.find("run"), std::string::npos);
  EXPECT_NE(top.out.find("grade"), std::string::npos);
}

TEST(RbsimRun, NoSceneIsAUsageError) {
  const test::Outcome o = rbsim({"run"});
  EXPECT_FALSE(o.timed_out);
  EXPECT_NE(o.exit_code, 0) << describe(o);
  EXPECT_NE(o.err.find("scene"), std::string::npos) << describe(o);
}

// ---------------------------------------------------------------------------------------------
// Output files of a 4-body wind scene over 50 steps, checked value by value against the library.
TEST(RbsimRun, OutputsHaveExactHeadersRowCountsAndBitExactValues) {
  const std::string scene = kScenes + "/windtests/test00sym.xml";  // four bodies at rest in wind
  const std::int64_t steps = 50;
  TempDir dir;
  const Outputs out = outputs_in(dir);
  std::vector<std::string> args = {"run", scene, "--steps", std::to_string(steps), "--quiet"};
  for (const std::string& a : output_args(out)) args.push_back(a);
  const test::Outcome o = rbsim(args);
  ASSERT_EQ(o.exit_code, 0) << describe(o);
  EXPECT_EQ(o.err, "") << "--quiet prints nothing on success";

  World w = world_of(scene);
  const auto bodies = w.body_count();
  ASSERT_EQ(bodies, 4);

  const auto csv = lines_of(read_text(out.csv));
  ASSERT_EQ(csv.size(), static_cast<std::size_t>(1 + bodies * (steps + 1)));
  EXPECT_EQ(csv[0], kCsvHeader);
  const auto energy = lines_of(read_text(out.energy));
  ASSERT_EQ(energy.size(), static_cast<std::size_t>(1 + steps + 1));
  EXPECT_EQ(energy[0], kEnergyHeader);
  EXPECT_EQ(fs::file_size(out.fosssim),
            sizeof(double) * static_cast<std::size_t>((16 * bodies + 1) + steps * (12 * bodies + 1)));
  EXPECT_TRUE(read_text(out.csv).ends_with("\n"));

  std::size_t row = 1;
  for (std::int64_t step = 0; step <= steps; ++step) {
    if (step > 0) w.step();
    for (std::int32_t b = 0; b < bodies; ++b, ++row) {
      const auto f = split(csv[row], ',');
      ASSERT_EQ(f.size(), 15u) << csv[row];
      EXPECT_EQ(f[0], std::to_string(step));
      EXPECT_TRUE(same_bits(parse_double(f[1]), w.time())) << csv[row];
      EXPECT_EQ(f[2], std::to_string(b));
      const BodyState s = w.state(BodyId{b});
      const BodyQuantities q = w.quantities(BodyId{b});
      const double expected[] = {s.position.x(), s.position.y(), s.theta,        s.velocity.x(),
                                 s.velocity.y(), s.omega,        q.momentum.x(), q.momentum.y(),
                                 q.l_point,      q.l_spin,       q.t_point,      q.t_spin};
      for (int k = 0; k < 12; ++k) {
        ASSERT_TRUE(same_bits(parse_double(f[3 + k]), expected[k]))
            << "step " << step << " body " << b << " column " << split(kCsvHeader, ',')[3 + k] << ": "
            << f[3 + k] << " vs " << expected[k];
      }
    }
    const auto e = split(energy[step + 1], ',');
    ASSERT_EQ(e.size(), 12u) << energy[step + 1];
    EXPECT_EQ(e[0], std::to_string(step));
    const Energy en = w.energy();
    EXPECT_TRUE(same_bits(parse_double(e[2]), en.potential()));
    EXPECT_TRUE(same_bits(parse_double(e[5]), en.kinetic()));
    EXPECT_TRUE(same_bits(parse_double(e[6]), en.total()));
    // wind only: no potential; the bodies speed up from rest, so kinetic energy grows
    EXPECT_EQ(parse_double(e[2]), 0.0);
    if (step > 0) {
      EXPECT_GT(parse_double(e[5]), parse_double(split(energy[step], ',')[5]));
    }
  }

  // FOSSSim binary: the state at t = 0, then M, X, I (spot checks; the grade tests read it whole)
  const std::string bin = read_text(out.fosssim);
  std::vector<double> v(bin.size() / sizeof(double));
  std::memcpy(v.data(), bin.data(), v.size() * sizeof(double));
  World w0 = world_of(scene);
  EXPECT_TRUE(same_bits(v[0], w0.x()[0]));
  EXPECT_TRUE(same_bits(v[6 * bodies], w0.mass(BodyId{0})));
  EXPECT_TRUE(same_bits(v[6 * bodies + bodies], w0.x()[0]));
  EXPECT_TRUE(same_bits(v[6 * bodies + 3 * bodies], w0.inertia(BodyId{0})));
  // last state block: body 0 x after `steps` steps
  const std::size_t last = (16 * bodies + 1) + (steps - 1) * (12 * bodies + 1);
  EXPECT_TRUE(same_bits(v[last], w.x()[0]));
  EXPECT_TRUE(same_bits(v.back(), w.potential_energy()));
}

TEST(RbsimRun, TwoRunsWriteBitIdenticalFiles) {
  const std::string scene = kScenes + "/springtests/test02sym.xml";  // springs and torques
  TempDir dir;
  const Outputs a = outputs_in(dir, "a"), b = outputs_in(dir, "b");
  for (const Outputs& out : {a, b}) {
    std::vector<std::string> args = {"run", scene, "--steps", "300", "-q"};
    for (const std::string& arg : output_args(out)) args.push_back(arg);
    const test::Outcome o = rbsim(args);
    ASSERT_EQ(o.exit_code, 0) << describe(o);
  }
  for (auto [x, y] :
       {std::pair{a.csv, b.csv}, std::pair{a.energy, b.energy}, std::pair{a.fosssim, b.fosssim}}) {
    const std::string tx = read_text(x), ty = read_text(y);
    EXPECT_GT(tx.size(), 1000u) << x;
    EXPECT_TRUE(tx == ty) << x << " and " << y << " differ";
  }
  // and the run really moved: the last rows differ from the first
  const auto rows = lines_of(read_text(a.csv));
  EXPECT_NE(split(rows[1], ',')[3], split(rows.back(), ',')[3]);
  // no temporary files are left behind
  std::size_t files = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir.path())) ++files;
  EXPECT_EQ(files, 6u);
}

std::size_t energy_rows(const std::vector<std::string>& extra, const std::string& scene) {
  TempDir dir;
  std::vector<std::string> args = {"run", scene, "-q", "--energy-csv", (dir / "e.csv").string()};
  args.insert(args.end(), extra.begin(), extra.end());
  const test::Outcome o = rbsim(args);
  EXPECT_EQ(o.exit_code, 0) << describe(o);
  return lines_of(read_text(dir / "e.csv")).size() - 1;
}

TEST(RbsimRun, StepsAndDurationOverrideTheScene) {
  const std::string scene = kScenes + "/gravitytests/test00ee.xml";  // 4 s at dt 0.01: 400 steps
  EXPECT_EQ(energy_rows({}, scene), 401u);
  EXPECT_EQ(energy_rows({"--steps", "7"}, scene), 8u);
  EXPECT_EQ(energy_rows({"--steps", "0"}, scene), 1u);
  EXPECT_EQ(energy_rows({"--duration", "0.07"}, scene), 9u);  // ceil(0.07 / 0.01) = 8 steps
  EXPECT_EQ(energy_rows({"--duration", "1"}, scene), 101u);
  EXPECT_EQ(energy_rows({"--duration", "0"}, scene), 1u);

  const test::Outcome both = rbsim({"run", scene, "--steps", "5", "--duration", "1"});
  EXPECT_NE(both.exit_code, 0) << describe(both);
  const test::Outcome negative = rbsim({"run", scene, "--steps", "-3"});
  EXPECT_NE(negative.exit_code, 0) << describe(negative);
}

TEST(RbsimRun, SummaryLineUnlessQuiet) {
  const test::Outcome o = rbsim({"run", kScenes + "/gravitytests/test01sym.xml", "--steps", "10"});
  ASSERT_EQ(o.exit_code, 0) << describe(o);
  ASSERT_EQ(o.err_lines().size(), 1u) << o.err;
  EXPECT_NE(o.err.find("test01sym"), std::string::npos) << o.err;
  EXPECT_NE(o.err.find("10 steps"), std::string::npos) << o.err;
  EXPECT_EQ(o.out, "");
}

// ---------------------------------------------------------------------------------------------
class RbsimRunBadScene : public ::testing::TestWithParam<test::BadScene> {};

TEST_P(RbsimRunBadScene, ExitsOneWithOneLocatedErrorLine) {
  const test::BadScene& bad = GetParam();
  const std::string path = kData + "/bad_scenes/" + bad.file;
  TempDir dir;
  const test::Outcome o = rbsim({"run", path, "--csv", (dir / "out.csv").string()});
  ASSERT_FALSE(o.timed_out);
  EXPECT_EQ(o.exit_code, 1) << describe(o);
  const auto lines = o.err_lines();
  ASSERT_EQ(lines.size(), 1u) << describe(o);
  const std::string lead = "rbsim run: error: ";
  ASSERT_EQ(lines[0].rfind(lead, 0), 0u) << lines[0];
  const std::string mismatch = bad.mismatch(path, lines[0].substr(lead.size()));
  EXPECT_TRUE(mismatch.empty()) << mismatch << "\n  got: " << lines[0];
  EXPECT_FALSE(fs::exists(dir / "out.csv")) << "no output for a bad scene";
  EXPECT_EQ(o.out, "");
}

INSTANTIATE_TEST_SUITE_P(Manifest, RbsimRunBadScene,
                         ::testing::ValuesIn(test::read_bad_scene_manifest(kData + "/bad_scenes")),
                         [](const auto& tp) { return tp.param.file.substr(0, tp.param.file.find('.')); });

TEST(RbsimRun, BadSceneManifestIsNotEmpty) {
  EXPECT_GE(test::read_bad_scene_manifest(kData + "/bad_scenes").size(), 40u);
}

TEST(RbsimRun, MissingSceneFileIsAClearError) {
  TempDir dir;
  const std::string path = (dir / "no_such_scene.xml").string();
  const test::Outcome o = rbsim({"run", path});
  EXPECT_EQ(o.exit_code, 1) << describe(o);
  ASSERT_EQ(o.err_lines().size(), 1u) << describe(o);
  EXPECT_EQ(o.err_lines()[0],
            "rbsim run: error: " + path + ": cannot open scene file: No such file or directory");
}

TEST(RbsimRun, UnwritableOutputIsAnError) {
  TempDir dir;
  const std::string path = (dir / "missing_dir" / "out.csv").string();
  const test::Outcome o = rbsim({"run", kScenes + "/gravitytests/test00ee.xml", "--csv", path});
  EXPECT_EQ(o.exit_code, 1) << describe(o);
  ASSERT_EQ(o.err_lines().size(), 1u) << describe(o);
  EXPECT_NE(o.err.find("missing_dir"), std::string::npos) << o.err;
}

TEST(RbsimRun, WarningsGoToStderrAndTheRunSucceeds) {
  TempDir dir;
  std::string text = read_text(kScenes + "/gravitytests/test00ee.xml");
  text.insert(text.find("<simtype"), "<camera zoom=\"2\"/>\n  ");
  test::write_text(dir / "warn.xml", text);
  const test::Outcome o = rbsim({"run", (dir / "warn.xml").string(), "--steps", "3", "-q"});
  EXPECT_EQ(o.exit_code, 0) << describe(o);
  ASSERT_EQ(o.err_lines().size(), 1u) << describe(o);
  EXPECT_EQ(o.err_lines()[0], (dir / "warn.xml").string() + ":2: warning: unknown node <camera> ignored");
}

// The explicit-Euler spring scene with every stiffness raised to 1e9: it diverges within 100 steps.
std::string stiff_scene_text() {
  std::string text = read_text(kScenes + "/springtests/test00ee.xml");
  const std::string k = "k=\"";
  for (std::size_t at = text.find(k); at != std::string::npos; at = text.find(k, at + 1)) {
    text.replace(at + k.size(), text.find('"', at + k.size()) - (at + k.size()), "1e9");
  }
  return text;
}

// A stiff explicit-Euler spring blows up: the run stops with a clear error at the first step
// whose state is not finite, and the outputs hold every step before it as complete files: the
// CSVs, and a finished, indexed MCAP recording that exports to the same CSV.
TEST(RbsimRun, DivergingSceneStopsWithAnErrorAndValidOutputs) {
  TempDir dir;
  std::string text = stiff_scene_text();
  test::write_text(dir / "stiff.xml", text);
  const test::Outcome o =
      rbsim({"run", (dir / "stiff.xml").string(), "-q", "--csv", (dir / "b.csv").string(), "--energy-csv",
             (dir / "e.csv").string(), "--record", (dir / "r.mcap").string()});
  EXPECT_EQ(o.exit_code, 1) << describe(o);
  ASSERT_EQ(o.err_lines().size(), 1u) << describe(o);
  EXPECT_NE(o.err.find("not finite"), std::string::npos) << o.err;
  // "... step N: body b x is not finite ... Outputs hold steps 0..N-1."
  const auto at = o.err.find("step ");
  ASSERT_NE(at, std::string::npos) << o.err;
  const long bad_step = std::stol(o.err.substr(at + 5));
  EXPECT_GT(bad_step, 10);
  EXPECT_NE(o.err.find("steps 0.." + std::to_string(bad_step - 1) + " (--allow-nonfinite keeps going)."),
            std::string::npos)
      << o.err;

  const auto energy = lines_of(read_text(dir / "e.csv"));
  ASSERT_EQ(energy.size(), static_cast<std::size_t>(1 + bad_step));
  EXPECT_EQ(energy[0], kEnergyHeader);
  for (std::size_t i = 1; i < energy.size(); ++i) EXPECT_EQ(split(energy[i], ',')[0], std::to_string(i - 1));
  const auto bodies = lines_of(read_text(dir / "b.csv"));
  ASSERT_EQ(bodies.size(), static_cast<std::size_t>(1 + 2 * bad_step));
  for (std::size_t i = 1; i < bodies.size(); ++i) {
    const auto f = split(bodies[i], ',');
    ASSERT_EQ(f.size(), 15u);
    for (int c = 3; c < 9; ++c)
      EXPECT_TRUE(std::isfinite(parse_double(f[c]))) << "state column " << c << ": " << bodies[i];
  }
  const test::Outcome doctor = rbsim({"log", "doctor", (dir / "r.mcap").string()});
  EXPECT_EQ(doctor.exit_code, 0) << describe(doctor);
  const test::Outcome exported =
      rbsim({"log", "export", (dir / "r.mcap").string(), "--csv", (dir / "x.csv").string()});
  ASSERT_EQ(exported.exit_code, 0) << describe(exported);
  EXPECT_EQ(read_text(dir / "x.csv"), read_text(dir / "b.csv"));
  // with --allow-nonfinite it runs to the end
  const test::Outcome all =
      rbsim({"run", (dir / "stiff.xml").string(), "-q", "--allow-nonfinite", "--steps", "2000"});
  EXPECT_EQ(all.exit_code, 0) << describe(all);
}

// Every command that simulates a scene runs it through the same driver: a divergence is one
// message, whichever command meets it (run and node add what their outputs hold).
TEST(RbsimRun, RenderAndPlotReportADivergenceAsRunDoes) {
  TempDir dir;
  std::string text = stiff_scene_text();
  test::write_text(dir / "stiff.xml", text);
  const test::Outcome run = rbsim({"run", (dir / "stiff.xml").string(), "-q"});
  ASSERT_EQ(run.exit_code, 1) << describe(run);
  const std::string prefix = "rbsim run: error: ";
  ASSERT_EQ(run.err.rfind(prefix, 0), 0u) << run.err;
  const auto end = run.err.find(". Outputs hold steps");
  ASSERT_NE(end, std::string::npos) << run.err;
  const std::string message = run.err.substr(prefix.size(), end - prefix.size());
  EXPECT_NE(message.find("is not finite: the simulation diverged"), std::string::npos) << message;

  const test::Outcome render =
      rbsim({"render", (dir / "stiff.xml").string(), "--out", (dir / "frames").string(), "--size", "64x48"});
  EXPECT_EQ(render.exit_code, 1) << describe(render);
  // (the first line: an ASan build's leak checker may add its report of suppressions after it)
  ASSERT_FALSE(render.err_lines().empty()) << describe(render);
  EXPECT_EQ(render.err_lines()[0], "rbsim render: error: " + message);
  const test::Outcome plot = rbsim({"plot", (dir / "stiff.xml").string(), "--out", (dir / "p.png").string()});
  EXPECT_EQ(plot.exit_code, 1) << describe(plot);
  ASSERT_FALSE(plot.err_lines().empty()) << describe(plot);
  EXPECT_EQ(plot.err_lines()[0], "rbsim plot: error: " + message);
  EXPECT_FALSE(fs::exists(dir / "p.png"));

  // The hint suggests the symplectic integrator only to a scene that does not use it already.
  EXPECT_NE(message.find("or the symplectic-euler integrator"), std::string::npos) << message;
  const std::string ee = "type=\"explicit-euler\"";
  ASSERT_NE(text.find(ee), std::string::npos);
  text.replace(text.find(ee), ee.size(), "type=\"symplectic-euler\"");
  test::write_text(dir / "stiff-se.xml", text);
  const test::Outcome se = rbsim({"run", (dir / "stiff-se.xml").string(), "-q"});
  ASSERT_EQ(se.exit_code, 1) << describe(se);
  EXPECT_NE(se.err.find("the simulation diverged (try a smaller dt)"), std::string::npos) << se.err;
  EXPECT_EQ(se.err.find("symplectic"), std::string::npos) << se.err;
}

}  // namespace
}  // namespace rbsim
