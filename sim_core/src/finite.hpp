// Whether a vector's components are finite: the check World's definition (world.cpp) and its
// changes between steps (control.cpp) make before a value reaches the state.
#pragma once

#include <cmath>

#include "rbsim/core.hpp"

namespace rbsim {

inline bool finite(const Vec2& v) {
  return std::isfinite(v.x()) && std::isfinite(v.y());
}

}  // namespace rbsim
