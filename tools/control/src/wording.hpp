// How the controller words a refused command and a step: one rule for controller.cpp and
// living_world.cpp.
#pragma once

#include <cstdint>
#include <string>

#include "rbsim/control.hpp"

namespace rbsim::control::detail {

inline CommandResult refuse(Refusal why, std::string message) {
  CommandResult r;
  r.successful = false;
  r.refusal = why;
  r.message = std::move(message);
  return r;
}
inline CommandResult failed(std::string message) {
  return refuse(Refusal::Other, std::move(message));
}
inline std::string at(std::int64_t step) {
  return "step " + std::to_string(step);
}

}  // namespace rbsim::control::detail
