// The golden verifier's own physics (physics.hpp): nothing here calls sim_core's step or energy.
#include "physics.hpp"

#include <cmath>

namespace rbsim::check {

namespace {

// The force of a spring on end i, pulling it towards end j when stretched (with l0 = 0 it is k d,
// no 0/0), added to the body at each end with its torque; d = end_j - end_i, length = |d|, arm_*
// the ends' offsets from their centres of mass.
void add_spring_force(const SpringDef& sp, const Vec2& d, double length, const Vec2& arm_i, const Vec2& arm_j,
                      std::vector<Vec2>& force, std::vector<double>& torque) {
  Vec2 f(0.0, 0.0);
  if (sp.rest_length == 0.0) {
    f = sp.stiffness * d;
  } else if (length > 0.0) {
    f = sp.stiffness * (length - sp.rest_length) / length * d;
  }
  if (sp.body_i >= 0) {
    force[sp.body_i] += f;
    torque[sp.body_i] += arm_i.x() * f.y() - arm_i.y() * f.x();
  }
  if (sp.body_j >= 0) {
    force[sp.body_j] -= f;
    torque[sp.body_j] -= arm_j.x() * f.y() - arm_j.y() * f.x();
  }
}

}  // namespace

Model model_of(const Scene& scene) {
  Model m;
  for (const BodyDef& b : scene.world.bodies) {
    double M = 0.0;
    Vec2 X(0.0, 0.0);
    for (std::size_t i = 0; i < b.hull.size(); ++i) {
      M += b.masses[i];
      X += b.masses[i] * b.hull[i];
    }
    X /= M;
    double I = 0.0;
    std::vector<Vec2> hull;
    for (std::size_t i = 0; i < b.hull.size(); ++i) {
      const Vec2 r = b.hull[i] - X;
      I += b.masses[i] * r.squaredNorm();
      hull.push_back(r);
    }
    m.mass.push_back(M);
    m.inertia.push_back(I);
    m.center.push_back(X);
    m.body_hull.push_back(std::move(hull));
  }
  m.springs = scene.world.springs;
  m.gravity = scene.world.gravity;
  return m;
}

Terms terms_of(const Model& m, const State& s) {
  const std::size_t n = m.mass.size();
  Terms t;
  std::vector<Vec2> force(n, Vec2(0.0, 0.0));
  std::vector<double> torque(n, 0.0);
  for (std::size_t b = 0; b < n; ++b) {
    const double M = m.mass[b], I = m.inertia[b];
    const Vec2 X(s.x[b], s.y[b]), V(s.vx[b], s.vy[b]);
    t.px.push_back(M * V.x());
    t.py.push_back(M * V.y());
    t.l_point.push_back(M * (X.x() * V.y() - X.y() * V.x()));
    t.l_spin.push_back(I * s.omega[b]);
    t.t_point.push_back(0.5 * M * V.squaredNorm());
    t.t_spin.push_back(0.5 * I * s.omega[b] * s.omega[b]);
    t.momentum_x += t.px.back();
    t.momentum_y += t.py.back();
    t.angular += t.l_point.back() + t.l_spin.back();
    t.kinetic_point += t.t_point.back();
    t.kinetic_spin += t.t_spin.back();
  }
  for (const GravityDef& g : m.gravity) {
    double u = 0.0;
    for (std::size_t b = 0; b < n; ++b) {
      u -= m.mass[b] * (g.acceleration.x() * s.x[b] + g.acceleration.y() * s.y[b]);
      force[b] += m.mass[b] * g.acceleration;
      t.scale += std::fabs(m.mass[b] * g.acceleration.x() * s.x[b]) +
                 std::fabs(m.mass[b] * g.acceleration.y() * s.y[b]);
    }
    t.force_potential.push_back(u);
  }
  auto end = [&](std::int32_t body, const Vec2& anchor, Vec2& arm) {
    if (body < 0) {
      arm = Vec2(0.0, 0.0);
      return anchor;
    }
    const double c = std::cos(s.theta[body]), sn = std::sin(s.theta[body]);
    arm = Vec2(c * anchor.x() - sn * anchor.y(), sn * anchor.x() + c * anchor.y());
    return Vec2(s.x[body] + arm.x(), s.y[body] + arm.y());
  };
  for (const SpringDef& sp : m.springs) {
    Vec2 arm_i, arm_j;
    SpringEnds e;
    e.end_i = end(sp.body_i, sp.anchor_i, arm_i);
    e.end_j = end(sp.body_j, sp.anchor_j, arm_j);
    const Vec2 d = e.end_j - e.end_i;
    e.length = d.norm();
    const double stretch = e.length - sp.rest_length;
    e.potential = 0.5 * sp.stiffness * stretch * stretch;
    t.springs.push_back(e);
    t.force_potential.push_back(e.potential);
    t.scale += e.potential;
    add_spring_force(sp, d, e.length, arm_i, arm_j, force, torque);
  }
  for (double u : t.force_potential) t.potential += u;
  t.total = t.potential + t.kinetic_point + t.kinetic_spin;
  t.scale += t.kinetic_point + t.kinetic_spin;
  for (std::size_t b = 0; b < n; ++b) {
    t.power += force[b].x() * s.vx[b] + force[b].y() * s.vy[b] + torque[b] * s.omega[b];
  }
  return t;
}

void step_state(const Model& m, const Scene& scene, State& s) {
  const std::size_t n = m.mass.size();
  std::vector<Vec2> force(n, Vec2(0.0, 0.0));
  std::vector<double> torque(n, 0.0);
  auto rotate = [&](std::size_t b, const Vec2& p) {
    const double c = std::cos(s.theta[b]), sn = std::sin(s.theta[b]);
    return Vec2(c * p.x() - sn * p.y(), sn * p.x() + c * p.y());
  };
  for (const GravityDef& g : m.gravity) {
    for (std::size_t b = 0; b < n; ++b) force[b] += m.mass[b] * g.acceleration;
  }
  for (const SpringDef& sp : m.springs) {
    const Vec2 arm_i =
        sp.body_i < 0 ? Vec2(0.0, 0.0) : rotate(static_cast<std::size_t>(sp.body_i), sp.anchor_i);
    const Vec2 arm_j =
        sp.body_j < 0 ? Vec2(0.0, 0.0) : rotate(static_cast<std::size_t>(sp.body_j), sp.anchor_j);
    const Vec2 pi = sp.body_i < 0 ? sp.anchor_i : Vec2(s.x[sp.body_i], s.y[sp.body_i]) + arm_i;
    const Vec2 pj = sp.body_j < 0 ? sp.anchor_j : Vec2(s.x[sp.body_j], s.y[sp.body_j]) + arm_j;
    const Vec2 d = pj - pi;
    const double l = d.norm();
    add_spring_force(sp, d, l, arm_i, arm_j, force, torque);
  }
  // F = sum over edges i and sample points j of beta l_i / P ((v_wind - v_j) . n_i) n_i, the
  // hull clockwise, so n = (-e.y, e.x) / |e| points out; sample j at (j + 1/2) / P along the edge.
  for (const WindDef& w : scene.world.winds) {
    const int P = w.points_per_edge;
    for (std::size_t b = 0; b < n; ++b) {
      const std::vector<Vec2>& hull = m.body_hull[b];
      const Vec2 V(s.vx[b], s.vy[b]);
      for (std::size_t i = 0; i < hull.size(); ++i) {
        const Vec2 a = rotate(b, hull[i]), c = rotate(b, hull[(i + 1) % hull.size()]);
        const Vec2 e = c - a;
        const double l = e.norm();
        if (l == 0.0) continue;
        const Vec2 normal(-e.y() / l, e.x() / l);
        for (int j = 0; j < P; ++j) {
          const Vec2 r = a + ((j + 0.5) / P) * e;  // from the centre of mass
          const Vec2 v = V + Vec2(-s.omega[b] * r.y(), s.omega[b] * r.x());
          const Vec2 f = w.beta * (l / P) * (w.velocity - v).dot(normal) * normal;
          force[b] += f;
          torque[b] += r.x() * f.y() - r.y() * f.x();
        }
      }
    }
  }
  const double dt = scene.world.dt;
  const bool symplectic = scene.world.integrator == Integrator::SymplecticEuler;
  for (std::size_t b = 0; b < n; ++b) {
    const double vx = s.vx[b], vy = s.vy[b], w = s.omega[b];
    s.vx[b] += dt * force[b].x() / m.mass[b];
    s.vy[b] += dt * force[b].y() / m.mass[b];
    s.omega[b] += dt * torque[b] / m.inertia[b];
    s.x[b] += dt * (symplectic ? s.vx[b] : vx);
    s.y[b] += dt * (symplectic ? s.vy[b] : vy);
    s.theta[b] += dt * (symplectic ? s.omega[b] : w);
  }
}

}  // namespace rbsim::check
