// libFuzzer target: spawnable fragments (parse_fragment: text -> Fragment, network input), and for
// fragments it accepts, the body added to a small running world as a spawn would add it (its
// springs' named ends on that world's body, fixed ends in space) and a few steps. Invariants: the
// parser never crashes or hangs on any text, its errors are one line naming the source, and what it
// accepts is one valid body within the limits.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "rbsim/core.hpp"
#include "rbsim/scene.hpp"

namespace {

// The running world a fragment is spawned into: one body, which every named end names.
rbsim::WorldDef host() {
  rbsim::WorldDef def;
  def.dt = 0.01;
  def.bodies.push_back({{{-1.0, -1.0}, {1.0, -1.0}, {0.0, 1.0}}, {1.0, 1.0, 2.0}, {0.0, 0.0}, 0.0, 0.1});
  def.gravity.push_back({{0.0, -9.81}});
  return def;
}

std::int32_t body_of(const rbsim::FragmentSpringEnd& end) {
  using Kind = rbsim::FragmentSpringEnd::Kind;
  if ((end.kind == Kind::Named) == end.body.empty()) __builtin_trap();  // a name exactly for Named
  if (end.kind == Kind::Self) return 1;
  return end.kind == Kind::Named ? 0 : rbsim::kFixed;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const rbsim::FragmentLimits limits;
  auto fragment = rbsim::parse_fragment(text, "fuzz.xml", limits);
  if (!fragment) {
    const std::string& m = fragment.error().message;
    if (m.rfind("fuzz.xml", 0) != 0 || m.find('\n') != std::string::npos) __builtin_trap();
    return 0;
  }
  const rbsim::Fragment& f = fragment.value();
  if (f.body.hull.size() < 2 || f.body.masses.size() != f.body.hull.size()) __builtin_trap();
  if (f.springs.size() > static_cast<std::size_t>(limits.max_springs)) __builtin_trap();
  // Bounded work per input: stepping large accepted bodies is not this target's job.
  if (f.body.hull.size() > 256 || f.springs.size() > 64) return 0;
  rbsim::WorldDef def = host();
  def.bodies.push_back(f.body);
  for (const rbsim::FragmentSpring& s : f.springs) {
    def.springs.push_back(
        {body_of(s.end_i), body_of(s.end_j), s.end_i.anchor, s.end_j.anchor, s.stiffness, s.rest_length});
  }
  auto world = rbsim::World::create(def);
  if (!world) __builtin_trap();  // an accepted fragment is a valid body wherever it is spawned
  rbsim::World& w = world.value();
  for (int i = 0; i < 8; ++i) {
    w.step();
    if (w.find_nonfinite()) break;
  }
  return 0;
}
