// libFuzzer target: the FOSSSim scene loader (text -> Scene), and for scenes it accepts, a few
// steps of the world and the scene/body-state messages through their decoders. Invariants: the
// loader never crashes or hangs on any text, and what it accepts builds a world whose messages
// decode back.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "rbsim/core.hpp"
#include "rbsim/msgs.hpp"
#include "rbsim/scene.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  auto scene = rbsim::parse_scene(text, "fuzz.xml");
  if (!scene) return 0;
  // Bounded work per input: large accepted scenes are fine, stepping them is not this target's job.
  const rbsim::WorldDef& def = scene.value().world;
  if (def.bodies.size() > 64 || def.springs.size() > 256) return 0;
  auto world = rbsim::World::create(def);
  if (!world) return 0;
  rbsim::World& w = world.value();
  for (int i = 0; i < 8; ++i) {
    w.step();
    if (w.find_nonfinite()) break;
  }
  const rbsim::msgs::Encoder encoder(scene.value());
  rbsim::msgs::Bytes bytes;
  encoder.scene(w, bytes);
  if (!rbsim::msgs::decode_scene(bytes)) __builtin_trap();  // our own message must decode
  encoder.body_states(w, bytes);
  rbsim::msgs::BodyStatesMessage states;
  if (!rbsim::msgs::decode_body_states(bytes, states)) __builtin_trap();
  if (states.bodies.size() != def.bodies.size()) __builtin_trap();
  return 0;
}
