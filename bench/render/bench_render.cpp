// Frames per second drawn at 1280x720 for a 100-body scene (gravity, wind, springs), drawing
// alone and drawing plus PNG encoding (what `rbsim render` does per frame).
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <filesystem>

#include "rbsim/builders.hpp"
#include "rbsim/render.hpp"

namespace {

struct Fixture {
  rbsim::Scene scene;
  rbsim::World world;
  rbsim::render::Stage stage;
  std::vector<rbsim::render::Pose> poses;
  rbsim::render::Camera camera;
  static Fixture make() {
    rbsim::Scene s;
    s.world = rbsim::builders::grid(100, /*wind_and_springs=*/true);
    for (int b = 0; b < 100; ++b) s.body_colors.push_back(rbsim::default_body_color(b));
    s.spring_colors.assign(100, rbsim::Color{0.3, 0.3, 0.3});
    s.duration = 10.0;
    auto w = rbsim::World::create(s.world);
    for (int i = 0; i < 500; ++i) w->step();  // a frame in motion, not the initial grid
    Fixture f{s, std::move(w.value()), {}, {}, {}};
    f.stage = rbsim::render::stage_of(f.scene, f.world);
    for (std::int32_t b = 0; b < f.world.body_count(); ++b) {
      f.poses.push_back({f.world.x()[b], f.world.y()[b], f.world.theta()[b]});
    }
    f.camera = rbsim::render::camera_for(f.stage, f.poses, 1280, 720);
    return f;
  }
};

void BM_Draw(benchmark::State& state) {
  Fixture f = Fixture::make();
  rbsim::render::Canvas canvas(1280, 720);
  for (auto _ : state) {
    canvas.draw(f.stage, f.poses, 1.0, f.camera);
    benchmark::DoNotOptimize(canvas.pixel(640, 360));
  }
  state.counters["fps"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_Draw)->Unit(benchmark::kMillisecond);

void BM_DrawAndWritePng(benchmark::State& state) {
  Fixture f = Fixture::make();
  rbsim::render::Canvas canvas(1280, 720);
  const std::string path =
      (std::filesystem::temp_directory_path() / ("rbsim_bench_frame_" + std::to_string(::getpid()) + ".png"))
          .string();
  for (auto _ : state) {
    canvas.draw(f.stage, f.poses, 1.0, f.camera);
    if (!canvas.write_png(path).ok()) state.SkipWithError("PNG write failed");
  }
  std::filesystem::remove(path);
  state.counters["fps"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_DrawAndWritePng)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
