#pragma once
#include <span>

#include "rbsim/core.hpp"

namespace rbsim {
// Edge sums of the closed-form wind force for a body-space hull sampled with P points per edge.
detail::WindMoments compute_wind_moments(std::span<const Vec2> hull, int points_per_edge);
}  // namespace rbsim
