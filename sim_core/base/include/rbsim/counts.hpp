// Counts in words, one rule each for every command's output: a noun's number (plural) and a
// large count's digits in groups of three (group_digits).
#pragma once

#include <concepts>
#include <cstdint>
#include <string>

namespace rbsim {

// `one` for exactly one, else `many` (0 bodies, 1 body, 2 bodies): a word,
// plural(n, "frame", "frames"), or an ending, "pass" + plural(n, "", "es").
template <std::integral N>
constexpr const char* plural(N n, const char* one, const char* many) {
  return n == 1 ? one : many;
}

// "1,234,567": the decimal digits of n, a comma between groups of three.
inline std::string group_digits(std::uint64_t n) {
  const std::string digits = std::to_string(n);
  std::string out;
  for (std::size_t i = 0; i < digits.size(); ++i) {
    if (i > 0 && (digits.size() - i) % 3 == 0) out += ',';
    out += digits[i];
  }
  return out;
}

}  // namespace rbsim
