// Every public FOSSSim scene that has a reference output is graded the way the reference grades
// (load its state, step once, compare), and our own free run is compared with its free run.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include <unistd.h>

#include "rbsim/fosssim.hpp"
#include "rbsim/sink.hpp"

namespace fs = std::filesystem;

namespace {

const fs::path kData = RBSIM_TEST_DATA;

std::vector<std::string> cases() {
  std::vector<std::string> out;
  for (const auto& e : fs::recursive_directory_iterator(kData / "fosssim" / "reference")) {
    if (e.path().extension() == ".zst") {
      out.push_back(fs::relative(e.path(), kData / "fosssim" / "reference").string());
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

class Reference : public testing::TestWithParam<std::string> {
 protected:
  void SetUp() override {
    const std::string rel = GetParam();
    const std::string stem = rel.substr(0, rel.size() - std::string(".bin.zst").size());
    rbsim::Result<rbsim::Scene> s =
        rbsim::load_scene((kData / "fosssim" / "scenes" / (stem + ".xml")).string());
    ASSERT_TRUE(s.ok()) << s.error().message;
    scene_ = s.value();
    auto bytes = rbsim::read_file((kData / "fosssim" / "reference" / rel).string());
    ASSERT_TRUE(bytes.ok()) << bytes.error().message;
    auto log = rbsim::parse_fosssim(bytes.value(), static_cast<std::int32_t>(scene_.world.bodies.size()));
    ASSERT_TRUE(log.ok()) << log.error().message;
    reference_ = log.value();
  }
  rbsim::Scene scene_;
  rbsim::FosssimLog reference_;
};

// The reference's own rule: per-step state difference < 1e-8, summed < 1e-6, quantities < 1e-8.
TEST_P(Reference, GradeMatchesReferenceRule) {
  auto report = rbsim::grade(scene_, reference_);
  ASSERT_TRUE(report.ok()) << report.error().message;
  const rbsim::GradeReport& r = report.value();
  EXPECT_TRUE(r.passed) << r.message;
  EXPECT_EQ(r.steps, scene_.step_count());
  RecordProperty("max_step_diff", std::to_string(r.max_step_diff));
  RecordProperty("max_quantity_diff", std::to_string(r.max_quantity_diff));
}

// A free run from t = 0 (no reloading) stays within 1e-9 of the reference's free run, value by
// value, for the whole duration, through the --fosssim-out sink.
TEST_P(Reference, FreeRunTracksReference) {
  const fs::path out =
      fs::path(testing::TempDir()) / (scene_.name + "_" + std::to_string(::getpid()) + ".bin");
  {
    auto created = rbsim::World::create(scene_.world);
    ASSERT_TRUE(created.ok());
    rbsim::World& w = created.value();
    auto sink = rbsim::make_fosssim_sink(out.string());
    ASSERT_TRUE(sink->begin(scene_, w).ok());
    while (w.step_index() < scene_.step_count()) {
      w.step();
      ASSERT_TRUE(sink->write(w).ok());
    }
    ASSERT_TRUE(sink->finish().ok());
  }
  auto mine_bytes = rbsim::read_file(out.string());
  fs::remove(out);
  ASSERT_TRUE(mine_bytes.ok());
  auto mine = rbsim::parse_fosssim(mine_bytes.value(), static_cast<std::int32_t>(scene_.world.bodies.size()));
  ASSERT_TRUE(mine.ok()) << mine.error().message;
  ASSERT_EQ(mine->frames.size(), reference_.frames.size());
  EXPECT_EQ(mine->mass, reference_.mass);
  EXPECT_EQ(mine->inertia, reference_.inertia);
  double worst = 0.0;
  for (std::size_t k = 0; k < reference_.frames.size(); ++k) {
    const auto& a = mine->frames[k];
    const auto& b = reference_.frames[k];
    for (std::size_t i = 0; i < a.states.size(); ++i) {
      for (double d :
           {a.states[i].position.x() - b.states[i].position.x(),
            a.states[i].position.y() - b.states[i].position.y(), a.states[i].theta - b.states[i].theta,
            a.states[i].velocity.x() - b.states[i].velocity.x(),
            a.states[i].velocity.y() - b.states[i].velocity.y(), a.states[i].omega - b.states[i].omega,
            a.quantities[i].l_point - b.quantities[i].l_point,
            a.quantities[i].t_point - b.quantities[i].t_point}) {
        worst = std::max(worst, std::abs(d));
      }
    }
    worst = std::max(worst, std::abs(a.potential - b.potential));
  }
  EXPECT_LT(worst, 1e-9);
  RecordProperty("free_run_max_diff", std::to_string(worst));
}

INSTANTIATE_TEST_SUITE_P(Fosssim, Reference, testing::ValuesIn(cases()),
                         [](const testing::TestParamInfo<std::string>& param_info) {
                           std::string name = param_info.param.substr(0, param_info.param.find('.'));
                           std::replace(name.begin(), name.end(), '/', '_');
                           return name;
                         });

TEST(ReferenceData, AllPublicReferencesPresent) {
  EXPECT_EQ(cases().size(), 38u);
}

}  // namespace
