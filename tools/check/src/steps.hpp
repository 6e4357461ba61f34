// rbsim check's step tracking, as plain data: the order of divergences (Key), a message waiting
// for its partner (Pending), and per topic and file the steps seen (StepTrack) and the steps in
// that file only (StepRuns). The report's sentences about them are in report.cpp (sentences.hpp).
#pragma once

#include <cstdint>
#include <vector>

#include "rbsim/mcap.hpp"

namespace rbsim::check {

// Ordering of divergences: the earliest in the golden (log time, then file position) is "first".
struct Key {
  std::uint64_t time = UINT64_MAX, ordinal = UINT64_MAX;
  bool operator<(const Key& o) const { return time != o.time ? time < o.time : ordinal < o.ordinal; }
};

struct Pending {
  mcap::Bytes data;
  mcap::Timestamp log_time = 0;
  std::uint64_t ordinal = 0;  // position among the file's messages
  std::uint64_t index = 0;    // position among the topic's messages
  std::uint64_t step = 0;     // simulated step (topics aligned by step)
};

// The steps a topic has in one file only, as arithmetic runs (0..999; 5, 15, ..., 995), at most
// kMaxRuns of them; step_runs_text() spells them out.
struct StepRuns {
  struct Run {
    std::uint64_t first = 0, last = 0, stride = 0, count = 0;
  };
  static constexpr std::size_t kMaxRuns = 6;
  std::vector<Run> runs;
  std::uint64_t count = 0, more_runs = 0;

  void add(std::uint64_t step) {
    ++count;
    if (!runs.empty()) {
      Run& r = runs.back();
      if (step > r.last && (r.count == 1 || step - r.last == r.stride)) {
        if (r.count == 1) r.stride = step - r.last;
        r.last = step;
        ++r.count;
        return;
      }
    }
    if (runs.size() < kMaxRuns) {
      runs.push_back({step, step, 0, 1});
    } else {
      ++more_runs;
    }
  }
};

// The steps of one topic in one file: first, last, and the smallest step between two messages.
struct StepTrack {
  bool any = false;
  std::uint64_t first = 0, last = 0, stride = 0, messages = 0;
  void add(std::uint64_t step) {
    if (any && step > last && (stride == 0 || step - last < stride)) stride = step - last;
    if (!any) first = step;
    any = true;
    last = step;
    ++messages;
  }
};

}  // namespace rbsim::check
