// rbsim check's value comparison: the tolerance and the per-field statistics (Values, Tally, plain
// data the report turns into rows), and the lockstep walker that compares two CDR messages value by
// value straight from their bytes through the one CDR cursor (msgs::CdrCursor, rbsim/cdr.hpp).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "layout.hpp"
#include "rbsim/check.hpp"
#include "rbsim/msgs.hpp"

namespace rbsim::check {

// The largest difference of one field group over all message pairs (a FieldStats row).
struct Stat {
  std::uint64_t values = 0, over = 0;
  double max_abs = 0.0, max_rel = 0.0;
  std::uint64_t step_at_max = 0;
};

// A topic's value statistics: one Stat per layout group (then the topic's own rows, "(bytes)" or
// "(log_time)"), and which groups are metadata (the scene description's name, description,
// viewport, background), reported apart from the physics and once each.
struct Tally {
  std::vector<Stat> stats;
  bool has_meta = false;
  std::vector<char> meta, meta_reported;
};

inline std::uint64_t step_value(const msgs::Scalar& s) {
  return s.kind == msgs::Scalar::Kind::Int ? static_cast<std::uint64_t>(s.i) : s.u;
}

// Compares value pairs (a: run, b: golden) within the options' tolerance and keeps the statistics:
// each Stat's maximum and the step it was at (a message's step may be known only after its walk:
// begin_message(), then at_step()), the values outside the tolerance and the metadata differences.
class Values {
 public:
  explicit Values(const CheckOptions& options) : o_(options) {}

  std::uint64_t diverging_values = 0;                    // values outside the tolerance
  std::vector<MetadataDifference> metadata_differences;  // first per field

  double atol() const { return o_.atol; }
  double rtol() const { return o_.rtol; }

  void begin_message() {
    touched_.clear();
    step_known_ = false;
  }
  // The message's step: the maxima found so far in it, and all later ones, are at this step.
  void at_step(std::uint64_t step) {
    for (Stat* st : touched_) st->step_at_max = step;
    step_known_ = true;
    cur_step_ = step;
  }

  // A decoded value pair: true when equal (NaN pairs match) or within the tolerance.
  bool same_scalar(Stat& st, const msgs::Scalar& a, const msgs::Scalar& b) {
    using Kind = msgs::Scalar::Kind;
    switch (b.kind) {
      case Kind::Float:
        if (a.f == b.f || (std::isnan(a.f) && std::isnan(b.f))) return true;
        break;
      case Kind::Int:
      case Kind::Bool:
        if (a.i == b.i) return true;
        break;
      case Kind::UInt:
      case Kind::Length:
        if (a.u == b.u && a.kind == b.kind) return true;
        break;
      case Kind::String:
        if (a.s == b.s) return true;
        break;
    }
    return differs(st, a, b);
  }

  // A value pair that is not bit-equal (a: run, b: golden): records the difference; false when it
  // is outside the tolerance (any difference, for everything but floats).
  bool differs(Stat& st, const msgs::Scalar& a, const msgs::Scalar& b) {
    using Kind = msgs::Scalar::Kind;
    double abs_diff = 1.0, rel = 1.0;
    bool ok = false;
    switch (b.kind) {
      case Kind::Float:
        return differs_float(st, a.f, b.f);
      case Kind::Int:
        if (a.i == b.i) return true;
        abs_diff = std::fabs(static_cast<double>(a.i) - static_cast<double>(b.i));
        rel = b.i != 0 ? abs_diff / std::fabs(static_cast<double>(b.i))
                       : std::numeric_limits<double>::infinity();
        break;
      case Kind::UInt:
      case Kind::Length:
        if (a.u == b.u) return true;
        abs_diff = std::fabs(static_cast<double>(a.u) - static_cast<double>(b.u));
        rel = b.u != 0 ? abs_diff / static_cast<double>(b.u) : std::numeric_limits<double>::infinity();
        break;
      case Kind::Bool:
        if (a.i == b.i) return true;
        break;
      case Kind::String:
        if (a.s == b.s) return true;
        break;
    }
    return record(st, abs_diff, rel, ok);
  }

  // differs() for floats, straight from the values: the hot case of a check in which every value
  // moved (another compiler or machine, compared with a tolerance).
  bool differs_float(Stat& st, double a, double b) {
    if (a == b || (std::isnan(a) && std::isnan(b))) return true;
    double abs_diff = std::fabs(a - b);
    if (std::isnan(abs_diff))
      abs_diff = std::numeric_limits<double>::infinity();  // NaN vs number, inf vs -inf
    const double rel = b != 0.0 ? abs_diff / std::fabs(b) : std::numeric_limits<double>::infinity();
    return record(st, abs_diff, rel, abs_diff <= o_.atol + o_.rtol * std::fabs(b));
  }

  // Inlined into the lockstep walker's flat-element loop (GCC otherwise calls it there, at twice
  // the cost).
  [[gnu::always_inline]] bool record(Stat& st, double abs_diff, double rel, bool ok) {
    if (abs_diff > st.max_abs) {
      st.max_abs = abs_diff;
      if (step_known_) {
        st.step_at_max = cur_step_;
      } else {
        touched_.push_back(&st);
      }
    }
    st.max_rel = std::max(st.max_rel, rel);
    if (!ok) {
      ++st.over;
      ++diverging_values;
    }
    return ok;
  }

  // A metadata value pair that differs (value number `index` of a golden message `golden_cdr` on
  // `topic`): reported once per field; true when it does not count as a divergence (without
  // strict_metadata). False for a group that is not metadata.
  bool metadata(Tally& t, const std::string& topic, const msgs::MessageDecoder& golden_decoder,
                std::uint32_t group, std::uint64_t index, const msgs::Scalar& run, const msgs::Scalar& golden,
                std::span<const std::byte> golden_cdr);

 private:
  const CheckOptions& o_;
  // Stats whose maximum changed before the message's step was known (fixed up by at_step()).
  std::vector<Stat*> touched_;
  bool step_known_ = false;
  std::uint64_t cur_step_ = 0;
};

// actual - expected as the report shows it ("differs" for strings and bools).
std::string difference(const msgs::Scalar& a, const msgs::Scalar& b);

// What a lockstep walk of a message pair found.
enum class Walk : std::uint8_t { Ok, Mismatch, Malformed };
struct WalkResult {
  // Ok; Mismatch at the first differing sequence length (the layouts part there); Malformed for
  // data that does not fit the schema (or not plain little-endian CDR).
  Walk walk = Walk::Malformed;
  std::uint64_t index = 0;               // values compared, in the decoder's scalar order
  std::uint64_t first_bad = UINT64_MAX;  // the first value outside the tolerance, or UINT64_MAX
  msgs::Scalar bad_a{}, bad_b{};         // its values (run, golden), for the divergence report
  bool has_step = false;                 // the golden message has a top-level "step" field
  std::uint64_t step = 0;                // ... with this value
};

// Walks a run message and a golden message of `topic` in lockstep straight from their CDR bytes,
// comparing every value as it goes into `tally` (its metadata reported with paths from
// `golden_decoder`). Stops at the first differing sequence length or at data that does not fit
// the layout; WalkResult::index then counts the values already compared.
WalkResult lockstep(Values& values, const Layout& layout, Tally& tally, const std::string& topic,
                    const msgs::MessageDecoder& golden_decoder, std::span<const std::byte> run,
                    std::span<const std::byte> golden);

}  // namespace rbsim::check
