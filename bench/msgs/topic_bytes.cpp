// Bytes a step costs on the wire (CDR payloads, the same in MCAP before compression, over DDS and
// over the Foxglove WebSocket server): every topic of msgs::topics() encoded for a world of N
// bodies (builders::grid(N, true): octagons, one spring each, gravity and wind), and the totals of
// the default topic set per published step and once (latched).
//
//   rbsim_bench_topic_bytes [N]   (default 1000)
#include <cstdio>
#include <cstdlib>

#include "rbsim/builders.hpp"
#include "rbsim/msgs.hpp"

int main(int argc, char** argv) {
  const int n = argc > 1 ? std::atoi(argv[1]) : 1000;
  rbsim::Scene scene;
  scene.name = "grid";
  scene.world = rbsim::builders::grid(n, /*wind_and_springs=*/true);
  scene.duration = 1.0;
  for (int b = 0; b < n; ++b) scene.body_colors.push_back(rbsim::default_body_color(b));
  scene.spring_colors.assign(scene.world.springs.size(),
                             rbsim::Color{0.25, 0.25, 0.25});  // the loader's default
  auto world = rbsim::World::create(scene.world);
  if (!world) {
    std::fprintf(stderr, "rbsim_bench_topic_bytes: %s\n", world.error().message.c_str());
    return 1;
  }
  for (int i = 0; i < 10; ++i) world->step();
  const rbsim::msgs::Encoder encoder(scene);
  const rbsim::msgs::TopicSet defaults = rbsim::msgs::default_topics();
  rbsim::msgs::Bytes out;
  std::size_t per_step = 0, once = 0;
  std::printf("%d bodies, %d springs: CDR bytes per message\n", n, world->spring_count());
  for (const rbsim::msgs::TopicSpec& spec : rbsim::msgs::topics()) {
    if (spec.event) continue;  // the controller's, not encoded from a World
    encoder.encode(spec.id, world.value(), out);
    const bool in_default = defaults.test(static_cast<std::size_t>(spec.id));
    std::printf("  %-28s %10zu  %s%s\n", rbsim::msgs::topic_name(spec, "rbsim").c_str(), out.size(),
                spec.per_step ? "every step" : "once (latched)", in_default ? "" : "  (not a default topic)");
    if (in_default) (spec.per_step ? per_step : once) += out.size();
  }
  std::printf("default topics: %zu bytes per published step, %zu bytes once\n", per_step, once);
  return 0;
}
