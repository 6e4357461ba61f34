// libFuzzer target: the YAML readers of the control module, command scripts (rbsim run --commands)
// and rcl parameter files (--params-file), on a small fixed scene. Invariants: neither crashes or
// hangs on any text; what a script reader accepts runs through the Controller without a crash,
// every command answered.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "rbsim/command_script.hpp"
#include "rbsim/ros_args.hpp"
#include "rbsim/run.hpp"

namespace {

constexpr std::string_view kScene = R"(<scene>
  <simtype type="rigid-body"/>
  <duration time="0.5"/>
  <rigidbodyintegrator type="symplectic-euler" dt="0.01"/>
  <rigidbodyvertex x="-1" y="-1" m="1"/><rigidbodyvertex x="-1" y="1" m="2"/><rigidbodyvertex x="1" y="0" m="1"/>
  <rigidbody p="0" p="1" p="2" vx="0.5" vy="0.0" omega="0.3" r="0.1"/>
  <rigidbodyvertex x="3" y="0" m="1"/><rigidbodyvertex x="4" y="0" m="1"/>
  <rigidbody p="3" p="4" vx="0.0" vy="1.0" omega="-0.5" r="0.1"/>
  <rigidbodygravityforce fx="0.0" fy="-9.81"/>
  <rigidbodywindforce beta="0.2" fx="1.0" fy="0.5" pointsperedge="3"/>
  <rigidbodyspringforce i="0" pix="0.5" piy="0.0" j="1" pjx="0.0" pjy="0.0" k="5.0" l0="2.0"/>
</scene>)";

const rbsim::Scene& scene() {
  static const rbsim::Scene s = rbsim::parse_scene(kScene, "fuzz.xml").value();
  return s;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  (void)rbsim::control::parse_params_yaml(text, "fuzz.yaml", "/rbsim");
  constexpr std::int64_t kSteps = 50;
  auto script = rbsim::control::parse_command_script(text, "fuzz.yaml", scene(), kSteps);
  if (!script) return 0;
  std::vector<rbsim::control::ScriptedCommand> commands;
  for (rbsim::control::Command& c : script.value()) {
    if (c.pause_seconds > 0.0) return 0;  // wall time: not this target's to spend
    commands.push_back({std::move(c), true, "fuzz"});
  }
  const std::size_t n = commands.size();
  rbsim::control::ScriptedRun run(scene(), kSteps, std::move(commands));
  auto driver = rbsim::Driver::create(scene());
  if (!driver) __builtin_trap();
  rbsim::DriverOptions options;
  options.steps = kSteps;
  options.allow_nonfinite = true;
  options.control = &run.controller();
  (void)driver.value().run_pass(options);
  (void)run.finish("fuzz.yaml");
  if (run.controller().counters().commands > 2 * n + 1)
    __builtin_trap();  // each answered once (and timed resumes)
  return 0;
}
