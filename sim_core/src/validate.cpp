// World::validate(): the invariants of the state arrays at a step boundary.
#include <cmath>
#include <string>

#include "rbsim/core.hpp"

namespace rbsim {

namespace {
Error broken(const std::string& what) {
  return Error{"world invariant broken: " + what};
}
bool positive_finite(double v) {
  return std::isfinite(v) && v > 0;
}
}  // namespace

Status World::validate() const {
  if (!positive_finite(dt_)) return broken("dt is not finite and > 0");
  if (step_ < 0) return broken("negative step index " + std::to_string(step_));
  const std::size_t n = x_.size();
  for (const std::vector<double>* column :
       {&y_, &theta_, &vx_, &vy_, &omega_, &fx_, &fy_, &tau_, &mass_, &inertia_, &radius_}) {
    if (column->size() != n) return broken("a per-body array does not hold one entry per body");
  }
  if (shape_.size() != n) return broken("the shape index does not hold one entry per body");
  const bool rotations = uses_rotations();
  if (rotations && (cos_.size() != n || sin_.size() != n))
    return broken("cos/sin do not hold one entry per body");
  if (wind_moments_.size() != winds_.size() * shapes_.size())
    return broken("one wind moment per wind and shape");
  for (const Shape& s : shapes_) {
    if (s.count < 2 || s.first < 0 || static_cast<std::size_t>(s.first) + s.count > shape_vertices_.size())
      return broken("a shape's vertices out of range");
  }
  for (std::size_t b = 0; b < n; ++b) {
    const auto body = [b](const char* what) { return broken("body " + std::to_string(b) + ": " + what); };
    if (!positive_finite(mass_[b]) || !positive_finite(inertia_[b]) || !positive_finite(radius_[b]))
      return body("mass, inertia and radius must be finite and > 0");
    if (shape_[b] < 0 || static_cast<std::size_t>(shape_[b]) >= shapes_.size())
      return body("shape index out of range");
    // sincos gives the bits of cos() and sin() (step.cpp): equality is exact, NaN aside.
    if (rotations && !std::isnan(theta_[b]) &&
        (cos_[b] != std::cos(theta_[b]) || sin_[b] != std::sin(theta_[b])))
      return body("cos/sin are not those of theta (state written without sync_rotations())");
  }
  for (std::size_t s = 0; s < springs_.size(); ++s) {
    for (const std::int32_t end : {springs_[s].body_i, springs_[s].body_j}) {
      if (end != kFixed && (end < 0 || static_cast<std::size_t>(end) >= n))
        return broken("spring " + std::to_string(s) + ": body index out of range");
    }
  }
  return Ok{};
}

}  // namespace rbsim
