// Writes seed inputs the fuzz targets cannot take from files in the repository as they are:
//   <out>/cdr/<topic>-<step>   one byte naming the type (TopicId), then a CDR message rbsim encoded
//   <out>/log/<scene>-<compression>.mcap   short recordings, one per chunk compression
//   <out>/interfaces/<n>-<i>   one byte naming the type (interface_types.hpp), then its CDR
// from the scenes given (a few steps each), so every seed is produced by the code it exercises.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "interface_types.hpp"
#include "rbsim/mcap_sink.hpp"
#include "rbsim/msgs.hpp"
#include "rbsim/scene.hpp"

namespace {
int fail(const std::string& m) {
  std::fprintf(stderr, "rbsim_fuzz_seeds: %s\n", m.c_str());
  return 1;
}

// Each interface type empty, the parameter messages with every kind of field filled, and
// simulation_interfaces' spawning and world types with sequences of nested messages.
void interface_seeds(const std::filesystem::path& dir) {
  namespace m = rbsim::msgs;
  std::filesystem::create_directories(dir);
  int n = 0;
  const auto write = [&](std::size_t index, const auto& message) {
    rbsim::Bytes bytes;
    encode(message, bytes);  // msgs' or simulation's: argument-dependent lookup
    std::ofstream f(dir / (std::to_string(n++) + "-" + std::to_string(index)), std::ios::binary);
    f.put(static_cast<char>(index));
    f.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  };
  for (std::size_t i = 0; i < rbsim::fuzz::kInterfaceCount; ++i) {
    rbsim::fuzz::with_interface(i, [&]<class T>() { write(i, T{}); });
  }
  m::ParameterValue v;
  v.type = m::ParameterType::StringArray;
  v.string_value = "forces.0.fy";
  v.byte_array_value = {1, 2};
  v.bool_array_value = {true};
  v.integer_array_value = {-1};
  v.double_array_value = {0.5};
  v.string_array_value = {"a", "bc"};
  m::ParameterDescriptor d;
  d.name = "rate";
  d.floating_point_range = m::FloatingPointRange{0, 10, 0};
  d.integer_range = m::IntegerRange{1, 5, 1};
  m::ParameterEvent e;
  e.node = "/rbsim";
  e.changed_parameters = {{"rate", v}};
  write(5, e);
  write(10, m::SetParametersRequest{{{"rate", v}, {"paused", {}}}});
  write(15, m::DescribeParametersResponse{{d}});
  // simulation_interfaces' nested sequences, filled.
  namespace sim = m::simulation;
  using rbsim::fuzz::interface_index;
  const sim::Resource resource{"file:///models/cart.sdf", "<sdf/>"};
  const sim::WorldResource world{"warehouse", resource, "indoor", {"indoor", "small"}};
  const sim::PoseStamped pose{{1, 2}, "map", {1.0, 2.0, 0.0}, m::quaternion_z(0.5)};
  write(interface_index<sim::SpawnEntitiesRequest>(),
        sim::SpawnEntitiesRequest{{{"cart", true, resource, "/fleet", pose}, {}}});
  write(interface_index<sim::SpawnEntitiesResponse>(),
        sim::SpawnEntitiesResponse{{150, "one failed"}, {{{101, "taken"}, "cart"}, {}}});
  write(interface_index<sim::GetSpawnablesResponse>(),
        sim::GetSpawnablesResponse{{1, ""}, {{resource, "cart", {1, {{1, 1, 1}, {-1, -1, 0}}}}}});
  write(interface_index<sim::GetAvailableWorldsRequest>(),
        sim::GetAvailableWorldsRequest{{"https://worlds"}, {{"indoor"}, 1}, true, true});
  write(interface_index<sim::GetAvailableWorldsResponse>(),
        sim::GetAvailableWorldsResponse{{1, ""}, {world, {}}});
  write(interface_index<sim::LoadWorldResponse>(), sim::LoadWorldResponse{{1, ""}, world});
}
}  // namespace

int main(int argc, char** argv) {
  namespace fs = std::filesystem;
  if (argc < 3) return fail("usage: rbsim_fuzz_seeds OUT_DIR SCENE.xml...");
  const fs::path out(argv[1]);
  fs::create_directories(out / "cdr");
  fs::create_directories(out / "log");
  interface_seeds(out / "interfaces");
  for (int i = 2; i < argc; ++i) {
    auto scene = rbsim::load_scene(argv[i]);
    if (!scene) return fail(scene.error().message);
    auto world = rbsim::World::create(scene.value().world);
    if (!world) return fail(world.error().message);
    const std::string stem = fs::path(argv[i]).stem().string();
    const rbsim::msgs::Encoder encoder(scene.value());
    rbsim::msgs::Bytes bytes;
    for (int step = 0; step <= 3; ++step) {
      for (const rbsim::msgs::TopicSpec& spec : rbsim::msgs::topics()) {
        if ((spec.id == rbsim::msgs::TopicId::SceneDescription && step > 0) || spec.event)
          continue;  // events: no World
        encoder.encode(spec.id, world.value(), bytes);
        std::ofstream f(out / "cdr" / (stem + "-" + std::string(spec.suffix) + "-" + std::to_string(step)),
                        std::ios::binary);
        f.put(static_cast<char>(spec.id));
        f.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
      }
      world.value().step();
    }
    for (const char* name : {"none", "lz4", "zstd"}) {
      rbsim::recordings::McapSinkOptions options;
      if (!rbsim::mcap::parse_compression(name, options.compression)) return fail(name);
      options.chunk_size = 4096;  // several chunks in a small file
      auto w = rbsim::World::create(scene.value().world);
      auto sink =
          rbsim::recordings::make_mcap_sink((out / "log" / (stem + "-" + name + ".mcap")).string(), options);
      if (!sink->begin(scene.value(), w.value())) return fail("cannot record " + stem);
      for (int step = 0; step < 4; ++step) {
        w.value().step();
        if (!sink->write(w.value())) return fail("cannot record " + stem);
      }
      if (!sink->finish()) return fail("cannot finish " + stem);
    }
  }
  return 0;
}
