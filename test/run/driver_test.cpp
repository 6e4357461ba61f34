// The run driver's contract: what each sink receives, and how a pass ends (done, stopped,
// diverged, sink error), over one pass and over several (rbsim node --loop).
#include <gtest/gtest.h>

#include <optional>
#include <string>
#include <vector>

#include "rbsim/run.hpp"

namespace rbsim {
namespace {

// Two bodies on a spring (explicit Euler); `k` makes it stiff enough to diverge.
Scene spring_scene(const std::string& k = "1.0") {
  const std::string text = R"(<scene>
  <simtype type="rigid-body"/>
  <duration time="1.0"/>
  <rigidbodyintegrator type="explicit-euler" dt="0.01"/>
  <rigidbodyvertex x="-5" y="-1" m="1"/><rigidbodyvertex x="-5" y="1" m="1"/>
  <rigidbodyvertex x="-3" y="1" m="1"/><rigidbodyvertex x="-3" y="-1" m="1"/>
  <rigidbody p="0" p="1" p="2" p="3" vx="0.0" vy="0.0" omega="0.0" r="0.1"/>
  <rigidbodyvertex x="3" y="-1" m="1"/><rigidbodyvertex x="3" y="1" m="1"/>
  <rigidbodyvertex x="5" y="1" m="1"/><rigidbodyvertex x="5" y="-1" m="1"/>
  <rigidbody p="4" p="5" p="6" p="7" vx="0.0" vy="0.0" omega="0.0" r="0.1"/>
  <rigidbodyspringforce i="0" pix="1.0" piy="0.0" j="1" pjx="-1.0" pjy="0.0" k=")" +
                           k + R"(" l0="4.0"/>
</scene>)";
  Result<Scene> scene = parse_scene(text, "spring.xml");
  if (!scene) throw std::runtime_error(scene.error().message);
  return std::move(scene.value());
}

// Records the step index of every call.
class Recorder final : public Sink {
 public:
  Status begin(const Scene&, const World& world) override {
    begun.push_back(world.step_index());
    return Ok{};
  }
  Status write(const World& world) override {
    written.push_back(world.step_index());
    if (fail_at && world.step_index() == fail_at) return Error{"disk full"};
    return Ok{};
  }
  Status finish() override {
    ++finished;
    return Ok{};
  }
  std::vector<std::int64_t> begun, written;
  int finished = 0;
  std::int64_t fail_at = 0;
};

std::vector<std::int64_t> range(std::int64_t first, std::int64_t last) {
  std::vector<std::int64_t> v;
  for (std::int64_t s = first; s <= last; ++s) v.push_back(s);
  return v;
}

TEST(Driver, EverySinkGetsStepZeroThenEveryStepThenFinish) {
  const Scene scene = spring_scene();
  Result<Driver> driver = Driver::create(scene);
  ASSERT_TRUE(driver.ok()) << driver.error().message;
  Recorder a, b;
  driver->add(a);
  driver->add(b);
  std::vector<std::int64_t> progress;
  DriverOptions options;
  options.steps = 25;
  options.progress = [&progress](std::int64_t step) { progress.push_back(step); };
  ASSERT_TRUE(driver->begin().ok());
  const Result<PassEnd> end = driver->run(options);
  ASSERT_TRUE(end.ok()) << end.error().message;
  EXPECT_EQ(end.value(), PassEnd::Done);
  ASSERT_TRUE(driver->finish().ok());
  for (const Recorder* r : {&a, &b}) {
    EXPECT_EQ(r->begun, std::vector<std::int64_t>{0});
    EXPECT_EQ(r->written, range(1, 25));
    EXPECT_EQ(r->finished, 1);
  }
  EXPECT_EQ(progress, range(1, 25));
  EXPECT_EQ(driver->world().step_index(), 25);
  EXPECT_EQ(driver->steps_done(), 25);
}

int g_polls = 0;
bool stop_after_ten_polls() {
  return ++g_polls > 10;
}

TEST(Driver, AStopRequestEndsThePassBeforeTheNextStep) {
  const Scene scene = spring_scene();
  Result<Driver> driver = Driver::create(scene);
  ASSERT_TRUE(driver.ok());
  Recorder r;
  driver->add(r);
  DriverOptions options;
  options.steps = 100;
  options.stop = stop_after_ten_polls;
  g_polls = 0;
  ASSERT_TRUE(driver->begin().ok());
  const Result<PassEnd> end = driver->run(options);
  ASSERT_TRUE(end.ok());
  EXPECT_EQ(end.value(), PassEnd::Stopped);
  EXPECT_EQ(r.written, range(1, 10));
  EXPECT_EQ(driver->world().step_index(), 10);
}

TEST(Driver, RunPassIsBeginRunFinishAndADivergenceIsItsError) {
  const Scene calm = spring_scene();
  Result<Driver> driver = Driver::create(calm);
  ASSERT_TRUE(driver.ok());
  Recorder r;
  driver->add(r);
  DriverOptions options;
  options.steps = 5;
  ASSERT_TRUE(driver->run_pass(options).ok());
  EXPECT_EQ(r.begun, std::vector<std::int64_t>{0});
  EXPECT_EQ(r.written, range(1, 5));
  EXPECT_EQ(r.finished, 1);

  const Scene stiff = spring_scene("1e9");
  Result<Driver> diverging = Driver::create(stiff);
  ASSERT_TRUE(diverging.ok());
  Recorder d;
  diverging->add(d);
  options.steps = 10000;
  const Status st = diverging->run_pass(options);
  ASSERT_FALSE(st.ok());
  EXPECT_EQ(st.error().message, describe_divergence(diverging->divergence()));
  EXPECT_EQ(d.finished, 0);  // a diverged pass leaves its outputs unfinished
}

TEST(Driver, ADivergenceEndsThePassWithoutWritingTheDivergedStep) {
  const Scene scene = spring_scene("1e9");
  Result<Driver> driver = Driver::create(scene);
  ASSERT_TRUE(driver.ok());
  Recorder r;
  driver->add(r);
  DriverOptions options;
  options.steps = 10000;
  ASSERT_TRUE(driver->begin().ok());
  const Result<PassEnd> end = driver->run(options);
  ASSERT_TRUE(end.ok());
  ASSERT_EQ(end.value(), PassEnd::Diverged);
  const Divergence& d = driver->divergence();
  EXPECT_EQ(d.step, driver->world().step_index());
  EXPECT_GT(d.step, 1);
  EXPECT_EQ(r.written, range(1, d.step - 1));
  const std::string message = describe_divergence(d);
  EXPECT_EQ(message.rfind("step " + std::to_string(d.step) + ": ", 0), 0u) << message;
  EXPECT_NE(message.find(std::string(d.quantity) + " is not finite: the simulation diverged"),
            std::string::npos)
      << message;

  // allow_nonfinite: every step is written, inf/NaN included.
  Result<Driver> again = Driver::create(scene);
  ASSERT_TRUE(again.ok());
  Recorder all;
  again->add(all);
  options.steps = d.step + 5;
  options.allow_nonfinite = true;
  ASSERT_TRUE(again->begin().ok());
  const Result<PassEnd> through = again->run(options);
  ASSERT_TRUE(through.ok());
  EXPECT_EQ(through.value(), PassEnd::Done);
  EXPECT_EQ(all.written, range(1, d.step + 5));
}

TEST(Driver, ASinkErrorEndsThePassAndIsReturned) {
  const Scene scene = spring_scene();
  Result<Driver> driver = Driver::create(scene);
  ASSERT_TRUE(driver.ok());
  Recorder failing, after;
  failing.fail_at = 7;
  driver->add(failing);
  driver->add(after);
  DriverOptions options;
  options.steps = 50;
  ASSERT_TRUE(driver->begin().ok());
  const Result<PassEnd> end = driver->run(options);
  ASSERT_FALSE(end.ok());
  EXPECT_EQ(end.error().message, "disk full");
  EXPECT_EQ(failing.written, range(1, 7));
  EXPECT_EQ(after.written, range(1, 6));  // the sinks after the failing one do not get that step
  EXPECT_EQ(failing.finished + after.finished, 0);
}

TEST(Driver, EveryPassStartsAgainFromStepZeroWithTheSameWorld) {
  const Scene scene = spring_scene();
  Result<Driver> driver = Driver::create(scene);
  ASSERT_TRUE(driver.ok());
  Recorder r;
  driver->add(r);
  DriverOptions options;
  options.steps = 8;
  std::vector<double> last_x;
  for (int pass = 0; pass < 3; ++pass) {
    ASSERT_TRUE(driver->begin().ok());
    EXPECT_EQ(driver->world().step_index(), 0);
    const Result<PassEnd> end = driver->run(options);
    ASSERT_TRUE(end.ok());
    EXPECT_EQ(end.value(), PassEnd::Done);
    last_x.push_back(driver->world().x()[0]);
  }
  ASSERT_TRUE(driver->finish().ok());
  EXPECT_EQ(r.begun, (std::vector<std::int64_t>{0, 0, 0}));
  EXPECT_EQ(r.written.size(), 24u);
  EXPECT_EQ(r.finished, 1);
  EXPECT_EQ(driver->steps_done(), 24);
  EXPECT_EQ(last_x[0], last_x[1]);  // bit for bit
  EXPECT_EQ(last_x[1], last_x[2]);
}

// The totals every output carries (energy CSV, EnergyTerms, plots): the per-body sums in body
// order from zero.
TEST(Driver, WorldTotalsAreThePerBodySums) {
  const Scene scene = spring_scene();
  Result<Driver> driver = Driver::create(scene);
  ASSERT_TRUE(driver.ok());
  DriverOptions options;
  options.steps = 30;
  ASSERT_TRUE(driver->begin().ok());
  ASSERT_TRUE(driver->run(options).ok());
  const World& w = driver->world();
  double px = 0.0, py = 0.0, l = 0.0;
  for (std::int32_t b = 0; b < w.body_count(); ++b) {
    const BodyQuantities q = w.quantities(BodyId{b});
    px += q.momentum.x();
    py += q.momentum.y();
    l += q.l_point + q.l_spin;
  }
  const SceneTotals t = w.totals();
  EXPECT_EQ(t.momentum.x(), px);
  EXPECT_EQ(t.momentum.y(), py);
  EXPECT_EQ(t.angular, l);
}

// The driver checks only the velocities against a limit after each step (World::finite_bound());
// it must still stop exactly where a full find_nonfinite() after every step would.
TEST(Driver, StopsWhereAnExactCheckAfterEveryStepStops) {
  for (const char* k : {"1e9", "1e5", "3e3"}) {
    const Scene scene = spring_scene(k);
    Result<World> reference = World::create(scene.world);
    ASSERT_TRUE(reference.ok());
    std::optional<World::NonFinite> expected;
    while (reference->step_index() < 10000 && !expected) {
      reference->step();
      expected = reference->find_nonfinite();
    }
    Result<Driver> driver = Driver::create(scene);
    ASSERT_TRUE(driver.ok());
    DriverOptions options;
    options.steps = 10000;
    ASSERT_TRUE(driver->begin().ok());
    const Result<PassEnd> end = driver->run(options);
    ASSERT_TRUE(end.ok());
    ASSERT_EQ(end.value() == PassEnd::Diverged, expected.has_value()) << "k = " << k;
    if (!expected) continue;
    EXPECT_EQ(driver->divergence().step, reference->step_index()) << "k = " << k;
    EXPECT_EQ(driver->divergence().body, expected->body.index);
    EXPECT_STREQ(driver->divergence().quantity, expected->quantity);
  }
}

TEST(Driver, AFiniteStateWhoseKineticEnergyOverflowsIsADivergence) {
  Scene scene = spring_scene();
  scene.world.bodies[1].velocity = {1e200, 0.0};  // T = M v^2 / 2 overflows; the state does not
  Result<Driver> driver = Driver::create(scene);
  ASSERT_TRUE(driver.ok());
  DriverOptions options;
  options.steps = 10;
  ASSERT_TRUE(driver->begin().ok());
  const Result<PassEnd> end = driver->run(options);
  ASSERT_TRUE(end.ok());
  ASSERT_EQ(end.value(), PassEnd::Diverged);
  EXPECT_EQ(driver->divergence().step, 1);
  EXPECT_EQ(driver->divergence().body, 1);
  EXPECT_STREQ(driver->divergence().quantity, "T_point");
}

}  // namespace
}  // namespace rbsim
