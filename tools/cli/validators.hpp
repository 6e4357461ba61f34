// CLI11 validators whose messages read well ("--steps: must be >= 0 (got -1)"); CLI11's own
// NonNegativeNumber prints its range with DBL_MAX written out in full.
#pragma once

#include <CLI/CLI.hpp>

#include <cstdio>
#include <cstdlib>
#include <string>

namespace rbsim::cli {

// A number at least `min` (strictly above it when `strict`). A value that is not a number passes
// here and is reported by the option's conversion ("Could not convert").
inline CLI::Validator at_least(double min, bool strict) {
  char bound[32];
  std::snprintf(bound, sizeof bound, "%g", min);
  const std::string rule = std::string(strict ? "must be > " : "must be >= ") + bound;
  return CLI::Validator(
      [min, strict, rule](std::string& value) -> std::string {
        char* end = nullptr;
        const double v = std::strtod(value.c_str(), &end);
        if (end == value.c_str() || *end != '\0') return {};
        if (strict ? v > min : v >= min) return {};
        return rule + " (got " + value + ")";
      },
      std::string(strict ? "> " : ">= ") + bound);
}
inline CLI::Validator non_negative() {
  return at_least(0, false);
}
inline CLI::Validator positive() {
  return at_least(0, true);
}

}  // namespace rbsim::cli
