// Scene builders shared by the tests and the benchmarks: worlds with known analytic behaviour
// and large synthetic worlds.
#pragma once

#include <string>

#include <cstdint>

#include "rbsim/core.hpp"

namespace rbsim::builders {

// A regular polygon hull, clockwise, centred at `center`, unit vertex masses.
BodyDef polygon(int vertices, double radius, Vec2 center, Vec2 velocity = {0.0, 0.0}, double omega = 0.0);

// A 2 x 2 square of four unit masses (M = 4, I = 8) at `center`.
BodyDef square(Vec2 center, Vec2 velocity = {0.0, 0.0}, double omega = 0.0);

// One square under gravity g (free fall: X(t) = X0 + V0 t + g t^2 / 2 in the continuum limit).
WorldDef free_fall(Integrator integrator, double dt, Vec2 g = {0.0, -9.81}, Vec2 v0 = {1.0, 2.0});

// One square on a spring to a fixed point through its centre of mass, rest length l0, stretched
// by `stretch`: harmonic along the spring with period 2 pi sqrt(M / k).
WorldDef fixed_spring(Integrator integrator, double dt, double k, double l0 = 1.0, double stretch = 0.5);

// Bodies with initial momenta and spins and no forces at all.
WorldDef free_bodies(Integrator integrator, double dt, int count);

// One square at rest in a uniform wind.
WorldDef square_in_wind(Integrator integrator, double dt, Vec2 wind, double beta = 1.0, int points = 4);

// N eight-vertex bodies on a grid. With `wind_and_springs` false: gravity only. With it:
// gravity, wind with 4 points per edge and one spring per body (to its neighbour, or to a fixed
// point for the last). `distinct_shapes` perturbs every hull so no two share a Shape.
WorldDef grid(std::int32_t n, bool wind_and_springs, bool distinct_shapes = true);

// The FOSSSim XML scene of a definition (numbers round-trip), so a command-line run and an
// in-process benchmark step the same world.
std::string to_scene_xml(const WorldDef& world, double duration);

}  // namespace rbsim::builders
