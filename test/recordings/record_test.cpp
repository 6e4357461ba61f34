// The MCAP sink at library level: the options it refuses.
#include <gtest/gtest.h>

#include "rbsim/scene.hpp"
#include "rbsim/subprocess.hpp"
#include "recordings_test_util.hpp"

namespace rbsim::test {
namespace {

namespace fs = std::filesystem;

// Recording every 0th (or -3rd) step is an error from begin(), not a silent every 1, and nothing
// is written.
TEST(McapSink, EveryBelowOneIsRefusedAtBegin) {
  Result<Scene> scene = load_scene(source_path("scenes/chain.xml"));
  ASSERT_TRUE(scene.ok()) << scene.error().message;
  Result<World> world = World::create(scene.value().world);
  ASSERT_TRUE(world.ok()) << world.error().message;
  TempDir dir;
  for (const std::int64_t every : {std::int64_t{0}, std::int64_t{-3}}) {
    const fs::path out = dir / ("every" + std::to_string(every) + ".mcap");
    recordings::McapSinkOptions o;
    o.every = every;
    const std::unique_ptr<Sink> sink = recordings::make_mcap_sink(out.string(), o);
    const Status st = sink->begin(scene.value(), world.value());
    ASSERT_FALSE(st.ok()) << "every " << every;
    EXPECT_NE(st.error().message.find("at least 1"), std::string::npos) << st.error().message;
    EXPECT_NE(st.error().message.find(out.string()), std::string::npos) << st.error().message;
    EXPECT_FALSE(fs::exists(out)) << out;
  }
}

}  // namespace
}  // namespace rbsim::test
