#include "rbsim/builders.hpp"

#include <cmath>
#include <cstdio>
#include <numbers>

namespace rbsim::builders {

BodyDef polygon(int vertices, double radius, Vec2 center, Vec2 velocity, double omega) {
  BodyDef b;
  for (int i = 0; i < vertices; ++i) {
    // decreasing angle: clockwise
    const double a = -2.0 * std::numbers::pi * i / vertices;
    b.hull.push_back(center + radius * Vec2(std::cos(a), std::sin(a)));
    b.masses.push_back(1.0);
  }
  b.velocity = velocity;
  b.omega = omega;
  return b;
}

BodyDef square(Vec2 center, Vec2 velocity, double omega) {
  BodyDef b;
  for (Vec2 corner : {Vec2(-1, -1), Vec2(-1, 1), Vec2(1, 1), Vec2(1, -1)}) {
    b.hull.push_back(center + corner);
    b.masses.push_back(1.0);
  }
  b.velocity = velocity;
  b.omega = omega;
  return b;
}

WorldDef free_fall(Integrator integrator, double dt, Vec2 g, Vec2 v0) {
  WorldDef w;
  w.integrator = integrator;
  w.dt = dt;
  w.bodies.push_back(square({0.0, 10.0}, v0, 0.0));
  w.gravity.push_back(GravityDef{g});
  return w;
}

WorldDef fixed_spring(Integrator integrator, double dt, double k, double l0, double stretch) {
  WorldDef w;
  w.integrator = integrator;
  w.dt = dt;
  w.bodies.push_back(square({l0 + stretch, 0.0}));
  SpringDef s;
  s.body_i = kFixed;
  s.anchor_i = {0.0, 0.0};
  s.body_j = 0;
  s.anchor_j = {0.0, 0.0};
  s.stiffness = k;
  s.rest_length = l0;
  w.springs.push_back(s);
  return w;
}

WorldDef free_bodies(Integrator integrator, double dt, int count) {
  WorldDef w;
  w.integrator = integrator;
  w.dt = dt;
  for (int i = 0; i < count; ++i) {
    w.bodies.push_back(polygon(3 + i % 5, 1.0 + 0.25 * i, {3.0 * i, -2.0 * i}, {0.5 - 0.3 * i, 1.0 + 0.1 * i},
                               0.7 - 0.4 * i));
  }
  return w;
}

WorldDef square_in_wind(Integrator integrator, double dt, Vec2 wind, double beta, int points) {
  WorldDef w;
  w.integrator = integrator;
  w.dt = dt;
  w.bodies.push_back(square({0.0, 0.0}));
  w.winds.push_back(WindDef{beta, wind, points});
  return w;
}

WorldDef grid(std::int32_t n, bool wind_and_springs, bool distinct_shapes) {
  WorldDef w;
  w.integrator = Integrator::SymplecticEuler;
  w.dt = 1e-3;
  const auto side = static_cast<std::int32_t>(std::ceil(std::sqrt(static_cast<double>(n))));
  w.bodies.reserve(static_cast<std::size_t>(n));
  for (std::int32_t i = 0; i < n; ++i) {
    const Vec2 c(3.0 * (i % side), 3.0 * (i / side));
    BodyDef b = polygon(8, 1.0, c, {0.1 * (i % 7), -0.05 * (i % 5)}, 0.01 * (i % 11));
    if (distinct_shapes) b.hull[0].x() += 1e-3 * (i % 997) / 997.0 + 1e-9 * i;
    w.bodies.push_back(std::move(b));
  }
  w.gravity.push_back(GravityDef{{0.0, -9.81}});
  if (wind_and_springs) {
    w.winds.push_back(WindDef{0.5, {2.0, 0.5}, 4});
    for (std::int32_t i = 0; i < n; ++i) {
      SpringDef s;
      s.body_i = i;
      s.anchor_i = {0.5, 0.0};
      s.body_j = i + 1 < n ? i + 1 : kFixed;
      s.anchor_j = i + 1 < n ? Vec2(-0.5, 0.0) : Vec2(0.0, 0.0);
      s.stiffness = 10.0;
      s.rest_length = 2.0;
      w.springs.push_back(s);
    }
  }
  return w;
}

std::string to_scene_xml(const WorldDef& world, double duration) {
  std::string out;
  char buf[256];
  const auto add = [&](const char* format, auto... values) {
    std::snprintf(buf, sizeof buf, format, values...);
    out += buf;
  };
  out += "<scene>\n  <simtype type=\"rigid-body\"/>\n";
  add("  <duration time=\"%.17g\"/>\n", duration);
  add("  <rigidbodyintegrator type=\"%s\" dt=\"%.17g\"/>\n", to_string(world.integrator), world.dt);
  std::size_t vertex = 0;
  for (const BodyDef& b : world.bodies) {
    for (std::size_t v = 0; v < b.hull.size(); ++v) {
      add("  <rigidbodyvertex x=\"%.17g\" y=\"%.17g\" m=\"%.17g\"/>\n", b.hull[v].x(), b.hull[v].y(),
          b.masses[v]);
    }
    out += "  <rigidbody";
    for (std::size_t v = 0; v < b.hull.size(); ++v) add(" p=\"%zu\"", vertex + v);
    add(" vx=\"%.17g\" vy=\"%.17g\" omega=\"%.17g\" r=\"%.17g\"/>\n", b.velocity.x(), b.velocity.y(), b.omega,
        b.radius);
    vertex += b.hull.size();
  }
  for (const SpringDef& s : world.springs) {
    add("  <rigidbodyspringforce i=\"%d\" pix=\"%.17g\" piy=\"%.17g\" j=\"%d\" pjx=\"%.17g\" pjy=\"%.17g\" "
        "k=\"%.17g\" "
        "l0=\"%.17g\"/>\n",
        s.body_i, s.anchor_i.x(), s.anchor_i.y(), s.body_j, s.anchor_j.x(), s.anchor_j.y(), s.stiffness,
        s.rest_length);
  }
  for (const GravityDef& g : world.gravity) {
    add("  <rigidbodygravityforce fx=\"%.17g\" fy=\"%.17g\"/>\n", g.acceleration.x(), g.acceleration.y());
  }
  for (const WindDef& w : world.winds) {
    add("  <rigidbodywindforce beta=\"%.17g\" fx=\"%.17g\" fy=\"%.17g\" pointsperedge=\"%d\"/>\n", w.beta,
        w.velocity.x(), w.velocity.y(), w.points_per_edge);
  }
  out += "</scene>\n";
  return out;
}

}  // namespace rbsim::builders
