// Scenes and a recording sink shared by the control tests.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "rbsim/control.hpp"
#include "rbsim/run.hpp"
#include "rbsim/scene.hpp"

namespace rbsim::test {

// Two bodies, a spring between them and one to a fixed point, forces in the file order gravity,
// wind, gravity (forces.0 gravity, forces.1 wind, forces.2 gravity). Each force's and spring's
// attributes are unique substrings, so a test edits one by replacing its text.
std::string control_scene_text();
Scene scene_from(const std::string& text);
inline Scene control_scene() {
  return scene_from(control_scene_text());
}

// A spawnable fragment (rbsim/scene.hpp) for the control scene: a triangle in its own frame (centre of mass
// at (1/3, 0) with these masses), spinning, with a spring from its vertex side to the scene's body_1 and one
// to a fixed point.
inline constexpr const char* kFragment = R"(<scene>
  <description text="a triangle"/>
  <rigidbodyvertex x="-1" y="-1" m="1"/><rigidbodyvertex x="-1" y="1" m="1"/>
  <rigidbodyvertex x="3" y="0" m="1"/>
  <rigidbody p="0" p="1" p="2" vx="0.25" vy="-0.5" omega="0.75" r="0.2"/>
  <rigidbodyspringforce i="0" pix="0.5" piy="0.25" jbody="body_1" pjx="0.0" pjy="0.5" k="7.0" l0="1.5"/>
  <rigidbodyspringforce i="-1" pix="2.0" piy="6.0" j="0" pjx="0.0" pjy="0.0" k="3.0" l0="0.5"/>
</scene>)";

// Another world for load_world: a falling square, one body, explicit Euler at dt 0.005, `duration`
// seconds long.
std::string square_world_text(const std::string& duration);

// A spawn of kFragment (named `name`, placed at `position`, rotated by `theta`) and a delete, each at
// `step`, from source "test".
inline control::Command spawn_command(std::int64_t step, std::string name, Vec2 position, double theta) {
  control::Command c;
  c.step = step;
  c.kind = control::CommandKind::Spawn;
  c.spawn.resource = kFragment;
  c.spawn.name = std::move(name);
  c.spawn.position = position;
  c.spawn.theta = theta;
  c.source = "test";
  return c;
}
inline control::Command delete_command(std::int64_t step, std::string name) {
  control::Command c;
  c.step = step;
  c.kind = control::CommandKind::Delete;
  c.entity = std::move(name);
  c.source = "test";
  return c;
}

// Every step a sink is given: the step index and the state arrays, in order.
struct Snapshot {
  std::int64_t step = 0;
  std::vector<double> state;  // x, y, theta, vx, vy, omega of every body
  bool operator==(const Snapshot&) const = default;
};
Snapshot snapshot(const World& world);

class RecordingSink final : public Sink {
 public:
  Status begin(const Scene&, const World& world) override;
  Status write(const World& world) override;
  Status finish() override { return Ok{}; }
  void rebase(const World&) override { ++rebases; }
  bool follows_structure() const override { return follows; }
  Status restructure(const World&, const Entities& e) override {
    entities.push_back(e);
    // A loaded world's scene lives while the controller keeps it (until the next world): its words
    // now, and no pointer kept.
    scene_descriptions.push_back(e.scene != nullptr ? e.scene->description : std::string());
    entities.back().scene = nullptr;
    return Ok{};
  }
  std::vector<Snapshot> snapshots;
  int rebases = 0;
  bool follows = true;
  std::vector<Entities> entities;               // at each restructure(), `scene` null
  std::vector<std::string> scene_descriptions;  // the scene's description at each restructure()
};

// One pass of `scene` for `steps` steps with an optional controller; the snapshots of every step.
// `entities`, when given, receives the sink's restructure() calls; `follows` says whether the sink
// follows structural changes; `descriptions`, when given, the description of each one's scene.
std::vector<Snapshot> run(const Scene& scene, std::int64_t steps, control::Controller* controller = nullptr,
                          std::vector<Entities>* entities = nullptr, bool follows = true,
                          std::vector<std::string>* descriptions = nullptr);

// Bit-for-bit equality of two doubles (memcmp: -0.0 differs from 0.0).
bool same_bits(const std::vector<double>& a, const std::vector<double>& b);

}  // namespace rbsim::test
