// The golden verifier's own physics, written from the spec (sections 4.6-4.8) and the README's
// conventions and sharing no code with sim_core, so that a bug in the simulator cannot hide in a
// golden: the scene's constants recomputed from its vertices, every recorded term recomputed from
// a body state, and an integrator that sums every force directly.
#pragma once

#include <vector>

#include "rbsim/core.hpp"
#include "rbsim/scene.hpp"

namespace rbsim::check {

// The scene's constant properties, recomputed from its file.
struct Model {
  std::vector<double> mass, inertia;
  std::vector<Vec2> center;                  // X at t = 0
  std::vector<std::vector<Vec2>> body_hull;  // body space
  std::vector<SpringDef> springs;
  std::vector<GravityDef> gravity;
};
Model model_of(const Scene& scene);

// The bodies' state at one step, one array per component.
struct State {
  std::vector<double> x, y, theta, vx, vy, omega;
};

struct SpringEnds {
  Vec2 end_i, end_j;
  double length = 0.0, potential = 0.0;
};

// Everything a step's energy, spring and pose messages should hold, from the state alone.
struct Terms {
  std::vector<double> px, py, l_point, l_spin, t_point, t_spin;
  std::vector<double> force_potential;  // each gravity field, then each spring
  std::vector<SpringEnds> springs;
  double momentum_x = 0.0, momentum_y = 0.0, angular = 0.0, potential = 0.0, kinetic_point = 0.0,
         kinetic_spin = 0.0, total = 0.0;
  double power = 0.0;  // sum F.V + tau omega of gravity and springs
  double scale = 0.0;  // sum of |term|: the size of the rounding error of the total
};
Terms terms_of(const Model& model, const State& state);

// One step of the scene's integrator from `state`: gravity, springs and the wind summed over its
// sample points (sim_core uses a closed form for the wind), rotations by cos/sin per point.
void step_state(const Model& model, const Scene& scene, State& state);

}  // namespace rbsim::check
