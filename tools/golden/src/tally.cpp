// The golden verifier's tallies and report lines (tally.hpp).
#include "tally.hpp"

#include <cmath>
#include <cstdio>

namespace rbsim::check {

std::string full_precision(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

std::string three_digits(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

void Tally::add(double got, double want, double tol, const std::function<std::string()>& where) {
  ++count_;
  double d = std::fabs(got - want);
  // inf - inf is NaN: equal infinities do not differ, anything else involving NaN is a failure.
  if (std::isnan(d)) d = got == want ? 0.0 : HUGE_VAL;
  if (d > max_) max_ = d;
  if (!(d <= tol) && fails_++ == 0) {
    first_ = where() + ": recorded " + full_precision(got) + ", expected " + full_precision(want) +
             " (tolerance " + three_digits(tol) + ")";
  }
}

void Tally::fail(const std::string& what) {
  if (fails_++ == 0) first_ = what;
}

std::string Tally::summary() const {
  return ok() ? "max diff " + three_digits(max_)
              : std::to_string(fails_) + " of " + std::to_string(count_) + " outside tolerance, first " +
                    first_;
}

void Report::line(bool ok, const std::string& what) {
  verification.lines.push_back((ok ? "PASS " : "FAIL ") + what);
  if (!ok) failed = true;
}

void Report::info(const std::string& what) {
  verification.lines.push_back("info " + what);
}

}  // namespace rbsim::check
