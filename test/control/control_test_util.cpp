#include "control_test_util.hpp"

#include <cstring>
#include <stdexcept>

namespace rbsim::test {

std::string control_scene_text() {
  return R"(<scene>
  <simtype type="rigid-body"/>
  <duration time="2.0"/>
  <rigidbodyintegrator type="symplectic-euler" dt="0.01"/>
  <rigidbodyvertex x="-3" y="-1" m="1"/><rigidbodyvertex x="-3" y="1" m="2"/>
  <rigidbodyvertex x="-1" y="1" m="1"/><rigidbodyvertex x="-1" y="-1" m="1"/>
  <rigidbody p="0" p="1" p="2" p="3" vx="0.5" vy="0.0" omega="0.3" r="0.1"/>
  <rigidbodyvertex x="2" y="-1" m="1"/><rigidbodyvertex x="2" y="1" m="1"/>
  <rigidbodyvertex x="4" y="0" m="3"/>
  <rigidbody p="4" p="5" p="6" vx="0.0" vy="1.0" omega="-0.5" r="0.1"/>
  <rigidbodygravityforce fx="0.0" fy="-9.81"/>
  <rigidbodywindforce beta="0.2" fx="1.0" fy="0.5" pointsperedge="3"/>
  <rigidbodyspringforce i="0" pix="0.5" piy="0.0" j="1" pjx="-0.5" pjy="0.2" k="5.0" l0="4.0"/>
  <rigidbodygravityforce fx="0.25" fy="0.0"/>
  <rigidbodyspringforce i="-1" pix="0.0" piy="5.0" j="0" pjx="0.0" pjy="0.5" k="20.0" l0="3.0"/>
</scene>)";
}

std::string square_world_text(const std::string& duration) {
  return R"(<scene>
  <simtype type="rigid-body"/>
  <description text="a falling square"/>
  <duration time=")" +
         duration + R"("/>
  <rigidbodyintegrator type="explicit-euler" dt="0.005"/>
  <rigidbodyvertex x="0" y="0" m="1"/><rigidbodyvertex x="1" y="0" m="1"/>
  <rigidbodyvertex x="1" y="1" m="1"/><rigidbodyvertex x="0" y="1" m="1"/>
  <rigidbody p="0" p="1" p="2" p="3" vx="1.5" vy="2.0" omega="0.7" r="0.1"/>
  <rigidbodygravityforce fx="0.0" fy="-9.81"/>
</scene>)";
}

Scene scene_from(const std::string& text) {
  Result<Scene> scene = parse_scene(text, "control.xml");
  if (!scene) throw std::runtime_error(scene.error().message);
  return std::move(scene.value());
}

Snapshot snapshot(const World& world) {
  Snapshot s;
  s.step = world.step_index();
  for (auto column : {world.x(), world.y(), world.theta(), world.vx(), world.vy(), world.omega()}) {
    s.state.insert(s.state.end(), column.begin(), column.end());
  }
  return s;
}

Status RecordingSink::begin(const Scene&, const World& world) {
  snapshots.push_back(snapshot(world));
  return Ok{};
}

Status RecordingSink::write(const World& world) {
  snapshots.push_back(snapshot(world));
  return Ok{};
}

std::vector<Snapshot> run(const Scene& scene, std::int64_t steps, control::Controller* controller,
                          std::vector<Entities>* entities, bool follows,
                          std::vector<std::string>* descriptions) {
  Result<Driver> driver = Driver::create(scene);
  if (!driver) throw std::runtime_error(driver.error().message);
  RecordingSink sink;
  sink.follows = follows;
  driver.value().add(sink);
  DriverOptions options;
  options.steps = steps;
  options.control = controller;
  if (Status st = driver.value().run_pass(options); !st) throw std::runtime_error(st.error().message);
  if (entities != nullptr) *entities = std::move(sink.entities);
  if (descriptions != nullptr) *descriptions = std::move(sink.scene_descriptions);
  return std::move(sink.snapshots);
}

bool same_bits(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}

}  // namespace rbsim::test
