// What World::create and World::add_body share, so a body added at run time gets the very bits a
// scene body with the same vertices gets (the same checks, the same sums in the same order).
#pragma once

#include <cstdint>
#include <vector>

#include "rbsim/core.hpp"

namespace rbsim::detail {

struct MassProperties {
  double mass = 0.0;     // M
  Vec2 com{0.0, 0.0};    // X at t = 0
  double inertia = 0.0;  // I about X
};

// The checks of one body and one spring of a definition; `index` names it in the message (-1: an
// added one). `bodies` bounds a spring's body indices.
Status validate_body(const BodyDef& body, std::int32_t index);
Status validate_spring(const SpringDef& spring, std::int32_t bodies, std::int32_t index);

// M, X and I of a validated body, and its hull in body space (vertex - X, in `local`).
Result<MassProperties> mass_properties(const BodyDef& body, std::int32_t index, std::vector<Vec2>& local);

}  // namespace rbsim::detail
