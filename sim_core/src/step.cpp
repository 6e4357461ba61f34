// The fixed force set and the integrators: plain passes over the state arrays.
#include <algorithm>
#include <cmath>

#include "rbsim/assert.hpp"
#include "rbsim/core.hpp"

namespace rbsim {

void World::step() {
  RBSIM_ASSERT(validate().ok(), "the world's arrays hold their invariants at a step boundary");
  std::fill(fx_.begin(), fx_.end(), 0.0);
  std::fill(fy_.begin(), fy_.end(), 0.0);
  std::fill(tau_.begin(), tau_.end(), 0.0);
  // Order fixed by the reference: all gravity, then all springs, then all wind.
  accumulate_gravity();
  accumulate_springs();
  accumulate_wind();
  integrate();
  // cos_/sin_ follow theta wherever springs or wind read them: the forces of the next step, and
  // spring_state() on the state this step leaves (the encoders ask for it several times a step).
  if (uses_rotations()) update_rotations();
  ++step_;
}

void World::update_rotations() {
  const std::int32_t n = body_count();
  // glibc's sincos gives the same bits as separate sin and cos at about half the cost; GCC does
  // not fuse the two calls itself while errno semantics are on.
  for (std::int32_t b = 0; b < n; ++b) ::sincos(theta_[b], &sin_[b], &cos_[b]);
}

// Near-earth gravity, U_i = -m_i g . r_i: the body feels F = M g at its centre of mass and no
// torque, since sum_i m_i r'_i = 0 in body space.
void World::accumulate_gravity() {
  const std::int32_t n = body_count();
  for (const GravityDef& g : gravity_) {
    const double gx = g.acceleration.x(), gy = g.acceleration.y();
    for (std::int32_t b = 0; b < n; ++b) {
      fx_[b] += mass_[b] * gx;
      fy_[b] += mass_[b] * gy;
    }
  }
}

namespace {
// Force on end i of a spring whose ends are at ri and rj: -dU/dri for U = k (l - l0)^2 / 2.
//
// l0 = 0: F = k (rj - ri), exact and smooth, and zero when the ends meet (the spec's special
// case, with no 0/0). l0 > 0 and l = 0: the direction is undefined (a point of maximal U in a
// radially symmetric potential); we apply no force, as for any isolated equilibrium, and the
// potential k l0^2 / 2 is still counted. Both rules keep NaN out of the state.
Vec2 spring_force_on_i(const SpringDef& sp, const Vec2& d, double l) {
  if (sp.rest_length == 0.0) return sp.stiffness * d;
  if (l == 0.0) return {0.0, 0.0};
  return (sp.stiffness * (l - sp.rest_length)) * (d / l);
}
}  // namespace

SpringState World::spring_state(SpringId id) const {
  const SpringDef& sp = springs_[id.index];
  auto end = [&](std::int32_t body, const Vec2& anchor) -> Vec2 {
    if (body == kFixed) return anchor;
    const double c = cos_[body], s = sin_[body];  // current: a world with springs keeps them so
    return {c * anchor.x() - s * anchor.y() + x_[body], s * anchor.x() + c * anchor.y() + y_[body]};
  };
  SpringState st;
  st.end_i = end(sp.body_i, sp.anchor_i);
  st.end_j = end(sp.body_j, sp.anchor_j);
  st.length = (st.end_j - st.end_i).norm();
  const double stretch = st.length - sp.rest_length;
  st.potential = 0.5 * sp.stiffness * stretch * stretch;
  return st;
}

// U = k (|rj - ri| - l0)^2 / 2 between two body points (or fixed points). The body at end i
// feels F at ri, i.e. force F and torque (ri - Xi) x F; end j feels -F.
void World::accumulate_springs() {
  for (const SpringDef& sp : springs_) {
    Vec2 arm_i = sp.anchor_i, arm_j = sp.anchor_j;  // R p: lever arms in world orientation
    Vec2 ri = sp.anchor_i, rj = sp.anchor_j;
    if (sp.body_i != kFixed) {
      const auto b = sp.body_i;
      arm_i = {cos_[b] * sp.anchor_i.x() - sin_[b] * sp.anchor_i.y(),
               sin_[b] * sp.anchor_i.x() + cos_[b] * sp.anchor_i.y()};
      ri = arm_i + Vec2(x_[b], y_[b]);
    }
    if (sp.body_j != kFixed) {
      const auto b = sp.body_j;
      arm_j = {cos_[b] * sp.anchor_j.x() - sin_[b] * sp.anchor_j.y(),
               sin_[b] * sp.anchor_j.x() + cos_[b] * sp.anchor_j.y()};
      rj = arm_j + Vec2(x_[b], y_[b]);
    }
    const Vec2 d = rj - ri;
    const Vec2 f = spring_force_on_i(sp, d, d.norm());
    if (sp.body_i != kFixed) {
      fx_[sp.body_i] += f.x();
      fy_[sp.body_i] += f.y();
      tau_[sp.body_i] += arm_i.x() * f.y() - arm_i.y() * f.x();
    }
    if (sp.body_j != kFixed) {
      fx_[sp.body_j] -= f.x();
      fy_[sp.body_j] -= f.y();
      tau_[sp.body_j] -= arm_j.x() * f.y() - arm_j.y() * f.x();
    }
  }
}

// d/dt (X, theta, V, omega) = (V, omega, F / M, tau / I)  (docs/rigid-body-milestone.md 3.4).
void World::integrate() {
  const std::int32_t n = body_count();
  const double h = dt_;
  if (integrator_ == Integrator::ExplicitEuler) {
    // Positions advance with the velocities of the start of the step.
    for (std::int32_t b = 0; b < n; ++b) {
      x_[b] += h * vx_[b];
      y_[b] += h * vy_[b];
      theta_[b] += h * omega_[b];
      vx_[b] += h * fx_[b] / mass_[b];
      vy_[b] += h * fy_[b] / mass_[b];
      omega_[b] += h * tau_[b] / inertia_[b];
    }
  } else {
    // Velocities first; positions advance with the new velocities.
    for (std::int32_t b = 0; b < n; ++b) {
      vx_[b] += h * fx_[b] / mass_[b];
      vy_[b] += h * fy_[b] / mass_[b];
      omega_[b] += h * tau_[b] / inertia_[b];
      x_[b] += h * vx_[b];
      y_[b] += h * vy_[b];
      theta_[b] += h * omega_[b];
    }
  }
}

}  // namespace rbsim
