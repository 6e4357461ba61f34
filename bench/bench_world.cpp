// World::step() throughput and memory per body, with Box2D 2.4.1 as a peer when available.
//
//   BM_Step/<case>/N     rbsim, builders::grid(N, ...): N eight-vertex bodies
//     gravity              gravity only
//     wind_springs         gravity + wind (4 points per edge) + one spring per body
//     *_shared             the same with every body sharing one hull Shape (the cheap case;
//                          the unsuffixed cases perturb every hull so no two share a Shape)
//   BM_Spawn/<case>/N    World::add_body of 1,000 bodies, one at a time, into the BM_Step world
//                        of N bodies (each a distinct eight-vertex hull, a new Shape): the cost
//                        of a spawn beside BM_Step's cost of a step of the same world
//   BM_Delete/<case>/N   World::remove_body of the first body (its spring with it), 1,000 times
//                        from N + 1,000: the stable erase's memmove of every later body
//   BM_Box2D/<case>/N    Box2D: the same N hulls as 8-vertex polygon fixtures on dynamic bodies,
//                        spaced so fat AABBs never overlap and filtered (maskBits 0) so no
//                        contact can ever exist; gravity on, sleeping off
//     gravity              world gravity only
//     wind_springs         plus, per body per step, a velocity-dependent drag force and torque
//                          and one spring force between neighbours at body points (ApplyForce)
//
// Counters:
//   ns_per_body_step   CPU time of the timed loop / (iterations * N)
//   bytes_per_body     rbsim: World::memory_bytes() / N (the budgeted figure)
//   heap_per_body      glibc heap growth (mallinfo2) across building the world / N: a check on
//                      memory_bytes() for rbsim, the only figure for Box2D
#include <benchmark/benchmark.h>
#include <malloc.h>
#include <string_view>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "rbsim/builders.hpp"
#include "rbsim/core.hpp"

#ifdef RBSIM_BENCH_BOX2D
#include <box2d/box2d.h>
#endif

namespace {

constexpr std::int64_t kSizes[] = {1, 100, 10'000, 100'000};

std::size_t heap_in_use() {
  const struct mallinfo2 mi = mallinfo2();
  return mi.uordblks + mi.hblkhd;
}

double cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// Runs `step` in the timed loop; ns_per_body_step = CPU time of the loop / (iterations * N).
// CPU time (the same clock as Google Benchmark's CPU column) rather than wall time because this
// 2-core machine is shared with builds; on an idle machine the two agree (scripts/bench prints
// both).
template <class Step>
void timed_steps(benchmark::State& state, std::int64_t n, Step&& step) {
  const double t0 = cpu_seconds();
  for (auto _ : state) {
    step();
    benchmark::ClobberMemory();
  }
  const double t1 = cpu_seconds();
  state.counters["ns_per_body_step"] =
      1e9 * (t1 - t0) / (static_cast<double>(state.iterations()) * static_cast<double>(n));
}

void bm_rbsim(benchmark::State& state, bool wind_and_springs, bool distinct_shapes) {
  const auto n = static_cast<std::int32_t>(state.range(0));
  const rbsim::WorldDef def = rbsim::builders::grid(n, wind_and_springs, distinct_shapes);
  const std::size_t heap0 = heap_in_use();
  auto created = rbsim::World::create(def);
  if (!created) {
    state.SkipWithError(created.error().message.c_str());
    return;
  }
  rbsim::World world = std::move(created.value());
  const std::size_t heap1 = heap_in_use();

  timed_steps(state, n, [&] { world.step(); });

  const auto bodies = static_cast<double>(n);
  state.counters["bytes_per_body"] = static_cast<double>(world.memory_bytes()) / bodies;
  state.counters["heap_per_body"] = static_cast<double>(heap1 - heap0) / bodies;
  state.counters["shapes"] = world.shape_count();
  benchmark::DoNotOptimize(world.x().data());
}

#ifdef RBSIM_BENCH_BOX2D
constexpr float kBox2DDt = 1e-3f;  // as builders::grid
constexpr float kBeta = 0.5f;      // as builders::grid's wind
const b2Vec2 kWind(2.0f, 0.5f);

struct Box2DScene {
  std::unique_ptr<b2World> world;
  std::vector<b2Body*> bodies;
};

Box2DScene make_box2d(const rbsim::WorldDef& def) {
  Box2DScene scene;
  scene.world = std::make_unique<b2World>(b2Vec2(0.0f, -9.81f));
  scene.world->SetAllowSleeping(false);
  scene.bodies.reserve(def.bodies.size());
  for (const rbsim::BodyDef& body : def.bodies) {
    rbsim::Vec2 com(0.0, 0.0);
    for (const rbsim::Vec2& v : body.hull) com += v;
    com /= static_cast<double>(body.hull.size());
    // Box2D wants counter-clockwise polygons; the builders' hulls are clockwise.
    b2Vec2 vertices[b2_maxPolygonVertices];
    const auto count = static_cast<std::int32_t>(body.hull.size());
    for (std::int32_t i = 0; i < count; ++i) {
      const rbsim::Vec2 r = body.hull[static_cast<std::size_t>(count - 1 - i)] - com;
      vertices[i].Set(static_cast<float>(r.x()), static_cast<float>(r.y()));
    }
    b2PolygonShape shape;
    shape.Set(vertices, count);

    b2BodyDef bd;
    bd.type = b2_dynamicBody;
    bd.position.Set(static_cast<float>(com.x()), static_cast<float>(com.y()));
    // Same spin as rbsim; no relative linear motion, so the lattice keeps its gaps and the
    // broadphase never sees an overlapping pair (Box2D's best case).
    bd.angularVelocity = static_cast<float>(body.omega);
    b2Body* b = scene.world->CreateBody(&bd);

    b2FixtureDef fd;
    fd.shape = &shape;
    fd.density = 1.0f;
    fd.filter.maskBits = 0;  // collides with nothing
    b->CreateFixture(&fd);
    scene.bodies.push_back(b);
  }
  return scene;
}

// The rbsim wind_springs force set, done by hand with Box2D's public API: a drag force and
// torque per body, and a spring between each body and the next at body points.
void box2d_forces(Box2DScene& scene) {
  const std::size_t n = scene.bodies.size();
  const b2Vec2 anchor_i(0.5f, 0.0f), anchor_j(-0.5f, 0.0f);
  for (std::size_t i = 0; i < n; ++i) {
    b2Body* b = scene.bodies[i];
    const b2Vec2 rel = kWind - b->GetLinearVelocity();
    b->ApplyForceToCenter(kBeta * 8.0f * rel, false);
    b->ApplyTorque(-kBeta * 4.0f * b->GetAngularVelocity(), false);
    const b2Vec2 ri = b->GetWorldPoint(anchor_i);
    const b2Vec2 rj = i + 1 < n ? scene.bodies[i + 1]->GetWorldPoint(anchor_j) : b2Vec2(0.0f, 0.0f);
    const b2Vec2 d = rj - ri;
    const float l = d.Length();
    if (l > 0.0f) {
      const b2Vec2 f = (10.0f * (l - 2.0f) / l) * d;
      b->ApplyForce(f, ri, false);
      if (i + 1 < n) scene.bodies[i + 1]->ApplyForce(-f, rj, false);
    }
  }
}

void bm_box2d(benchmark::State& state, bool wind_and_springs) {
  const auto n = static_cast<std::int32_t>(state.range(0));
  const rbsim::WorldDef def = rbsim::builders::grid(n, wind_and_springs, true);
  const std::size_t heap0 = heap_in_use();
  Box2DScene scene = make_box2d(def);
  scene.world->Step(kBox2DDt, 8, 3);  // first step allocates the solver's stack and contact arrays
  const std::size_t heap1 = heap_in_use();

  if (wind_and_springs) {
    timed_steps(state, n, [&] {
      box2d_forces(scene);
      scene.world->Step(kBox2DDt, 8, 3);
    });
  } else {
    timed_steps(state, n, [&] { scene.world->Step(kBox2DDt, 8, 3); });
  }

  state.counters["heap_per_body"] = static_cast<double>(heap1 - heap0) / static_cast<double>(n);
  state.counters["contacts"] = scene.world->GetContactCount();
  benchmark::DoNotOptimize(scene.bodies.data());
}
#endif

// 1,000 spawns (BM_Spawn) or deletes (BM_Delete) one at a time, as the node applies them at
// step boundaries; counter ns_per_change, and ns_per_body_step of one step of the world as it
// ends, for the ratio.
constexpr std::int64_t kChanges = 1000;

void bm_structure(benchmark::State& state, bool wind_and_springs, bool spawn) {
  const auto n = static_cast<std::int32_t>(state.range(0));
  const rbsim::WorldDef def =
      rbsim::builders::grid(n + (spawn ? 0 : static_cast<std::int32_t>(kChanges)), wind_and_springs, true);
  // The bodies to spawn: the grid's next ones (distinct hulls), placed where they would stand.
  const rbsim::WorldDef more =
      rbsim::builders::grid(n + static_cast<std::int32_t>(kChanges), wind_and_springs, true);
  double ns = 0.0;
  for (auto _ : state) {
    state.PauseTiming();
    auto created = rbsim::World::create(def);
    if (!created) {
      state.SkipWithError(created.error().message.c_str());
      return;
    }
    rbsim::World world = std::move(created.value());
    world.reserve(n + static_cast<std::int32_t>(kChanges), static_cast<std::int32_t>(more.springs.size()));
    state.ResumeTiming();
    const double t0 = cpu_seconds();
    for (std::int64_t k = 0; k < kChanges; ++k) {
      if (spawn) {
        const rbsim::BodyDef& b = more.bodies[static_cast<std::size_t>(n + k)];
        const rbsim::Result<rbsim::BodyHandle> h =
            world.add_body(b, rbsim::BodyState{b.hull[0], 0.0, b.velocity, 0.0});
        if (!h) state.SkipWithError(h.error().message.c_str());
      } else if (!world.remove_body(world.handle(rbsim::BodyId{0})).ok()) {
        state.SkipWithError("remove_body refused");
      }
    }
    ns += 1e9 * (cpu_seconds() - t0);
    benchmark::DoNotOptimize(world.x().data());
  }
  state.counters["ns_per_change"] = ns / (static_cast<double>(state.iterations()) * kChanges);
}

void register_all() {
  struct Case {
    const char* name;
    bool wind_and_springs;
    bool distinct_shapes;
  };
  static constexpr Case kCases[] = {
      {"BM_Step/gravity", false, true},
      {"BM_Step/wind_springs", true, true},
      {"BM_Step/gravity_shared", false, false},
      {"BM_Step/wind_springs_shared", true, false},
  };
  for (const Case& c : kCases) {
    auto* b = benchmark::RegisterBenchmark(c.name, bm_rbsim, c.wind_and_springs, c.distinct_shapes);
    for (std::int64_t n : kSizes) b->Arg(n);
    b->Unit(benchmark::kMicrosecond);
  }
  for (bool wind : {false, true}) {
    for (bool spawn : {true, false}) {
      const std::string name =
          std::string(spawn ? "BM_Spawn/" : "BM_Delete/") + (wind ? "wind_springs" : "gravity");
      benchmark::RegisterBenchmark(name.c_str(), bm_structure, wind, spawn)
          ->Arg(10'000)
          ->Unit(benchmark::kMillisecond);
    }
  }
#ifdef RBSIM_BENCH_BOX2D
  for (bool wind : {false, true}) {
    auto* b =
        benchmark::RegisterBenchmark(wind ? "BM_Box2D/wind_springs" : "BM_Box2D/gravity", bm_box2d, wind);
    for (std::int64_t n : kSizes) b->Arg(n);
    b->Unit(benchmark::kMicrosecond);
  }
#endif
}

}  // namespace

int main(int argc, char** argv) {
  // rbsim_bench_world --scene gravity|wind_springs N: the XML of a BM_Step case's world, for
  // scripts/bench-runner to time `rbsim run` on exactly the world BM_Step steps.
  if (argc == 4 && std::string_view(argv[1]) == "--scene") {
    const std::string_view which = argv[2];
    if (which != "gravity" && which != "wind_springs") return 2;
    const rbsim::WorldDef def = rbsim::builders::grid(std::stoi(argv[3]), which == "wind_springs", true);
    std::fputs(rbsim::builders::to_scene_xml(def, 1000.0).c_str(), stdout);
    return 0;
  }
  register_all();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
