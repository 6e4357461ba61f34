// How the golden verifier counts and words its comparisons: a Tally per check, a Report of the
// PASS / FAIL / info lines.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "rbsim/golden.hpp"

namespace rbsim::check {

// `v` with 17 significant digits (enough to read the double back) and with 3 (for tolerances
// and summaries).
std::string full_precision(double v);
std::string three_digits(double v);

// `get` of every element of `items`, as doubles: one recorded field of a message's sequence.
template <class T, class Get>
std::vector<double> field(const std::vector<T>& items, Get get) {
  std::vector<double> out;
  out.reserve(items.size());
  for (const T& item : items) out.push_back(static_cast<double>(get(item)));
  return out;
}

// The largest deviation of a set of comparisons, and the first one outside its tolerance.
// `where` is called only for that first one, so callers can build the text lazily.
class Tally {
 public:
  void add(double got, double want, double tol, const std::function<std::string()>& where);
  void fail(const std::string& what);
  bool ok() const { return fails_ == 0; }
  double max() const { return max_; }
  std::uint64_t count() const { return count_; }
  std::string summary() const;

 private:
  std::uint64_t count_ = 0, fails_ = 0;
  double max_ = 0.0;
  std::string first_;
};

// The lines of a verification, and whether one of them failed.
struct Report {
  GoldenVerification& verification;
  void line(bool ok, const std::string& what);
  void info(const std::string& what);
  bool failed = false;
};

}  // namespace rbsim::check
