// Changes to a world between steps: parameter sets and impulses (World::set_*, apply_impulse).
// step() never sees a half-made change: callers make them at step boundaries only.
#include <cmath>
#include <string>

#include "finite.hpp"
#include "rbsim/core.hpp"
#include "wind_moments.hpp"

namespace rbsim {

namespace {
Error refused(const std::string& what) {
  return Error{what, ErrorCode::InvalidArgument};
}
}  // namespace

Status World::set_gravity(std::int32_t field, const Vec2& acceleration) {
  if (field < 0 || static_cast<std::size_t>(field) >= gravity_.size()) {
    return refused("no gravity field " + std::to_string(field));
  }
  if (!finite(acceleration)) return refused("gravity must be finite");
  gravity_[field].acceleration = acceleration;
  finite_bound_ = compute_finite_bound();  // |g| enters the bound on U_gravity
  return Ok{};
}

Status World::set_wind(std::int32_t wind, const WindDef& def) {
  if (wind < 0 || static_cast<std::size_t>(wind) >= winds_.size())
    return refused("no wind " + std::to_string(wind));
  if (!(std::isfinite(def.beta) && def.beta >= 0)) return refused("wind beta must be finite and >= 0");
  if (!finite(def.velocity)) return refused("wind velocity must be finite");
  if (def.points_per_edge < 1) return refused("wind points per edge must be >= 1");
  const bool resample = def.points_per_edge != winds_[wind].points_per_edge;
  winds_[wind] = def;
  if (resample) {
    // Only the torque's omega term d depends on P (through mean(s^2) = 1/3 - 1/(12 P^2), see
    // wind.cpp); the moments are recomputed whole, in place, for every shape under this wind.
    const std::size_t shapes = shapes_.size();
    for (std::size_t k = 0; k < shapes; ++k) {
      const Shape& shape = shapes_[k];
      const std::span<const Vec2> hull(shape_vertices_.data() + shape.first, shape.count);
      wind_moments_[static_cast<std::size_t>(wind) * shapes + k] =
          compute_wind_moments(hull, def.points_per_edge);
    }
  }
  return Ok{};  // wind does not enter finite_bound(): it is dissipative
}

Status World::set_spring(SpringId s, double stiffness, double rest_length) {
  if (s.index < 0 || s.index >= spring_count()) return refused("no spring " + std::to_string(s.index));
  if (!(std::isfinite(stiffness) && stiffness >= 0)) return refused("spring k must be finite and >= 0");
  if (!(std::isfinite(rest_length) && rest_length >= 0)) return refused("spring l0 must be finite and >= 0");
  springs_[s.index].stiffness = stiffness;
  springs_[s.index].rest_length = rest_length;
  finite_bound_ = compute_finite_bound();  // k and l0 enter the bound on U_spring
  return Ok{};
}

// An impulse J is a force integrated over a vanishing time: it changes the velocities at once and
// the positions not at all. Linear momentum P = M V gains exactly J (N s = kg m/s), so
// V += J / M. About the centre of mass, J applied at the world lever arm r = R(theta) p adds the
// angular impulse r x J = r.x J.y - r.y J.x (z component, CCW positive, kg m^2/s), so
// omega += (r x J) / I. The total angular momentum about the world origin gains (X + r) x J: the
// L_point part X x J through V, the L_spin part r x J through omega.
Status World::apply_impulse(BodyId b, const Vec2& impulse, const Vec2& point) {
  if (b.index < 0 || b.index >= body_count()) return refused("no body " + std::to_string(b.index));
  if (!finite(impulse)) return refused("impulse must be finite");
  if (!finite(point)) return refused("impulse point must be finite");
  const auto i = b.index;
  double s = 0.0, c = 1.0;
  ::sincos(theta_[i], &s, &c);  // as update_rotations(): the rotation step() uses
  const double rx = c * point.x() - s * point.y(), ry = s * point.x() + c * point.y();
  vx_[i] += impulse.x() / mass_[i];
  vy_[i] += impulse.y() / mass_[i];
  omega_[i] += (rx * impulse.y() - ry * impulse.x()) / inertia_[i];
  return Ok{};
}

}  // namespace rbsim
