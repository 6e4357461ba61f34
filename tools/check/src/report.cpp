// The text report of a comparison: what `rbsim check` prints and what rbsim::testing::CheckLogs
// puts in a failed assertion's message (one formatter, so the two never read differently).
#include <algorithm>
#include <cstdarg>
#include <cstdio>

#include "rbsim/check.hpp"

namespace rbsim::check {

namespace {

std::string g(double v, const char* format = "%.3g") {
  char buf[40];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

void append(std::string& out, const char* format, ...) __attribute__((format(printf, 2, 3)));
void append(std::string& out, const char* format, ...) {
  char buf[1024];
  va_list args;
  va_start(args, format);
  const int n = std::vsnprintf(buf, sizeof buf, format, args);
  va_end(args);
  if (n < 0) return;
  if (static_cast<std::size_t>(n) < sizeof buf) {
    out.append(buf, static_cast<std::size_t>(n));
    return;
  }
  std::string big(static_cast<std::size_t>(n) + 1, '\0');
  va_start(args, format);
  std::vsnprintf(big.data(), big.size(), format, args);
  va_end(args);
  big.pop_back();
  out += big;
}

void append_table(std::string& out, const CheckReport& r, bool all_fields) {
  std::size_t topic_w = 5, field_w = 5;
  std::size_t identical = 0;
  std::vector<const FieldStats*> rows;
  for (const FieldStats& f : r.fields) {
    if (!all_fields && f.max_abs == 0.0 && f.over == 0) {
      ++identical;
      continue;
    }
    rows.push_back(&f);
    topic_w = std::max(topic_w, f.topic.size());
    field_w = std::max(field_w, f.field.size());
  }
  out += "per-field max error (run - golden, array indices collapsed):\n";
  if (!rows.empty()) {
    append(out, "  %-*s  %-*s  %-6s  %10s  %10s  %10s  %12s  %10s\n", static_cast<int>(topic_w), "topic",
           static_cast<int>(field_w), "field", "kind", "values", "max |diff|", "max rel", "at", "over tol");
    for (const FieldStats* f : rows) {
      const std::string at =
          f->max_abs == 0.0 ? "-" : (f->has_step ? "step " : "msg ") + std::to_string(f->step_at_max);
      append(out, "  %-*s  %-*s  %-6s  %10llu  %10s  %10s  %12s  %10llu\n", static_cast<int>(topic_w),
             f->topic.c_str(), static_cast<int>(field_w), f->field.c_str(), f->kind.c_str(),
             static_cast<unsigned long long>(f->values), g(f->max_abs).c_str(), g(f->max_rel).c_str(),
             at.c_str(), static_cast<unsigned long long>(f->over));
    }
  }
  if (identical > 0) {
    append(out, "  %s%zu field%s identical%s\n", rows.empty() ? "all " : "", identical,
           identical == 1 ? "" : "s", all_fields || rows.empty() ? "" : " (--all-fields lists them)");
  }
}

}  // namespace

std::string format_report(const std::string& run, const std::string& golden, const CheckOptions& options,
                          const CheckReport& r, const ReportFormat& format) {
  std::string out;
  append(out, "rbsim check: %s vs golden %s (atol %s, rtol %s): %s\n", run.c_str(), golden.c_str(),
         g(options.atol, "%g").c_str(), g(options.rtol, "%g").c_str(), r.passed() ? "MATCH" : "DIVERGED");
  if (!r.scene_mismatch.empty()) {
    out += "different scenes: " + r.scene_mismatch + "\n";
    return out;
  }
  if (r.first) out += "first divergence: " + r.first->line() + "\n";
  for (const std::string& p : r.topic_problems) out += "topic difference: " + p + "\n";
  for (const std::string& p : r.step_problems) out += "steps in one file only: " + p + "\n";
  if (!r.metadata.empty()) {
    append(out, "metadata differs (%s):\n",
           options.strict_metadata ? "a divergence with --strict-metadata"
                                   : "not physics, reported only; --strict-metadata fails on it");
    for (const MetadataDifference& m : r.metadata) out += "  " + m.line() + "\n";
  }
  append_table(out, r, format.all_fields);
  const double mb = static_cast<double>(r.run_bytes + r.golden_bytes) / 1e6;
  append(out, "%zu topic%s, %llu message pair%s, %s MB of message data", r.topics.size(),
         r.topics.size() == 1 ? "" : "s", static_cast<unsigned long long>(r.messages),
         r.messages == 1 ? "" : "s", g(mb).c_str());
  if (format.wall_seconds) {
    const double wall = *format.wall_seconds;
    append(out, " in %s s (%s MB/s)", g(wall).c_str(), g(wall > 0 ? mb / wall : 0.0).c_str());
  }
  if (!r.passed() && (r.diverging_values > 0 || r.one_file_messages == 0)) {
    append(out, "; %llu values in %llu messages differ", static_cast<unsigned long long>(r.diverging_values),
           static_cast<unsigned long long>(r.diverging_messages - r.one_file_messages));
  }
  if (r.one_file_messages > 0) {
    append(out, "; %llu messages in one file only", static_cast<unsigned long long>(r.one_file_messages));
  }
  out += "\n";
  return out;
}

}  // namespace rbsim::check
