// The text report of a comparison: what `rbsim check` prints and what rbsim::testing::CheckLogs
// puts in a failed assertion's message (one formatter, so the two never read differently), and
// every sentence in it (sentences.hpp): the comparer keeps plain data and asks here for its text.
#include <algorithm>
#include <charconv>
#include <cstdarg>
#include <cstdio>
#include <vector>

#include "rbsim/check.hpp"
#include "rbsim/counts.hpp"
#include "sentences.hpp"

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
           plural(identical, "", "s"), all_fields || rows.empty() ? "" : " (--all-fields lists them)");
  }
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// The sentences (sentences.hpp).

std::string ordinal(std::uint64_t n) {
  const std::uint64_t tens = n % 100, ones = n % 10;
  const char* suffix = (tens >= 11 && tens <= 13) ? "th"
                       : ones == 1                ? "st"
                       : ones == 2                ? "nd"
                       : ones == 3                ? "rd"
                                                  : "th";
  return std::to_string(n) + suffix;
}

std::string fmt_short(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

std::string value_text(const msgs::Scalar& s) {
  if (s.kind != msgs::Scalar::Kind::Float) return s.to_string();
  char buf[40];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, s.f, std::chars_format::general);  // shortest
  return ec == std::errc() ? std::string(buf, end) : s.to_string();
}

const char* to_string(msgs::Scalar::Kind k) {
  using Kind = msgs::Scalar::Kind;
  switch (k) {
    case Kind::Bool:
      return "bool";
    case Kind::Int:
      return "int";
    case Kind::UInt:
      return "uint";
    case Kind::Float:
      return "float";
    case Kind::String:
      return "string";
    case Kind::Length:
      return "length";
  }
  return "?";
}

std::string quoted(const std::string& s) {
  return s.empty() ? "(none)" : "'" + s + "'";
}

std::string step_runs_text(const StepRuns& runs) {
  std::string out;
  for (const StepRuns::Run& r : runs.runs) {
    if (!out.empty()) out += ", ";
    if (r.count == 1) {
      out += std::to_string(r.first);
    } else if (r.stride == 1) {
      out += std::to_string(r.first) + ".." + std::to_string(r.last);
    } else if (r.count <= 3) {
      for (std::uint64_t k = 0; k < r.count; ++k)
        out += (k > 0 ? ", " : "") + std::to_string(r.first + k * r.stride);
    } else {
      out += std::to_string(r.first) + ", " + std::to_string(r.first + r.stride) + ", ..., " +
             std::to_string(r.last);
    }
  }
  if (runs.more_runs > 0) out += " and more";
  return out;
}

std::string only_summary(const StepRuns& runs, bool golden_only, const StepTrack& r, const StepTrack& g) {
  std::string out = std::string(golden_only ? "run lacks steps " : "run has extra steps ") +
                    step_runs_text(runs) + " (" + group_digits(runs.count) +
                    plural(runs.count, " message", " messages");
  std::vector<std::string> hints;
  if (r.stride != 0 && g.stride != 0 && r.stride != g.stride) {
    hints.push_back("golden recorded " +
                    (g.stride == 1 ? "every step" : "every " + ordinal(g.stride) + " step") + ", run " +
                    (r.stride == 1 ? "every step" : "every " + ordinal(r.stride)) + " (--record-every)");
  } else if (!runs.runs.empty()) {
    const StepTrack& mine = golden_only ? g : r;
    const StepTrack& other = golden_only ? r : g;
    const bool leading = runs.runs.front().first == mine.first && other.any && mine.first < other.first;
    const bool trailing = runs.runs.back().last == mine.last && other.any && mine.last > other.last;
    if (golden_only) {
      if (leading) hints.push_back("recorder joined late?");
      if (trailing) hints.push_back("the run ends at step " + std::to_string(other.last));
      if (!other.any) hints.push_back("the run has none");
      if (!leading && !trailing && other.any) hints.push_back("messages lost?");
    } else {
      if (leading)
        hints.push_back("the run starts before the golden's first step " + std::to_string(other.first));
      if (trailing)
        hints.push_back("the run goes on past the golden's last step " + std::to_string(other.last));
      if (!other.any) hints.push_back("the golden has none");
    }
  }
  for (std::size_t i = 0; i < hints.size(); ++i) out += (i == 0 ? ": " : "; ") + hints[i];
  return out + ")";
}

std::string scene_difference(const msgs::SceneMessage& golden, const msgs::SceneMessage& run) {
  const auto counts = [](const std::string& what, std::size_t g, std::size_t r) {
    return what + ": golden " + std::to_string(g) + ", run " + std::to_string(r);
  };
  if (golden.bodies.size() != run.bodies.size())
    return counts("bodies", golden.bodies.size(), run.bodies.size());
  if (golden.springs.size() != run.springs.size())
    return counts("springs", golden.springs.size(), run.springs.size());
  if (golden.gravity.size() != run.gravity.size())
    return counts("gravity fields", golden.gravity.size(), run.gravity.size());
  if (golden.winds.size() != run.winds.size())
    return counts("wind fields", golden.winds.size(), run.winds.size());
  if (golden.integrator != run.integrator) {
    return "integrator: golden '" + golden.integrator + "', run '" + run.integrator + "'";
  }
  for (std::size_t i = 0; i < golden.bodies.size(); ++i) {
    if (golden.bodies[i].hull.size() != run.bodies[i].hull.size()) {
      return counts("hull vertices of body " + std::to_string(i), golden.bodies[i].hull.size(),
                    run.bodies[i].hull.size());
    }
  }
  const auto end = [](std::int32_t b) { return b == kFixed ? std::string("fixed") : std::to_string(b); };
  for (std::size_t i = 0; i < golden.springs.size(); ++i) {
    const SpringDef& g = golden.springs[i];
    const SpringDef& r = run.springs[i];
    if (g.body_i != r.body_i || g.body_j != r.body_j) {
      return "spring " + std::to_string(i) + " joins bodies " + end(g.body_i) + "-" + end(g.body_j) +
             " in the golden, " + end(r.body_i) + "-" + end(r.body_j) + " in the run";
    }
  }
  return "";
}

std::string different_scenes(const msgs::SceneMessage& golden, const msgs::SceneMessage& run,
                             const std::string& why) {
  return "the run and the golden record different scenes (golden " + quoted(golden.name) + ", run " +
         quoted(run.name) + "): " + why;
}

std::string topic_only_in(const std::string& role, std::uint64_t messages) {
  return "topic only in the " + role + " (" + std::to_string(messages) + " messages)";
}

std::string schema_differs(const std::string& golden, const std::string& run) {
  return "schema differs: golden " + quoted(golden) + ", run " + quoted(run);
}

std::string encoding_differs(const std::string& golden_message, const std::string& golden_schema,
                             const std::string& run_message, const std::string& run_schema) {
  return "encoding differs: golden " + golden_message + "/" + golden_schema + ", run " + run_message + "/" +
         run_schema;
}

std::string fields_differ(const std::string& schema) {
  return "schema " + schema + " defines different fields in the two files";
}

std::string message_in_one_file(bool golden_only) {
  return golden_only ? "message missing from the run" : "extra message in the run";
}

std::string messages_left_over(bool golden_only, std::uint64_t run_messages, std::uint64_t golden_messages) {
  return golden_only ? "message missing from the run: the golden has " + std::to_string(golden_messages) +
                           " messages on this topic, the run " + std::to_string(run_messages)
                     : "extra message in the run: the run has " + std::to_string(run_messages) +
                           " messages on this topic, the golden " + std::to_string(golden_messages);
}

FirstDifference topic_difference(const std::string& topic, const std::string& what) {
  FirstDifference d;
  d.topic = topic;
  d.topic_level = true;
  d.field = "(" + what + ")";
  return d;
}

FirstDifference message_difference(const std::string& topic, bool has_step, std::uint64_t step,
                                   const std::string& what) {
  return FirstDifference{topic, has_step, step, "(" + what + ")", "", "", ""};
}

void add_detail(FirstDifference& d, const std::string& detail) {
  d.field = d.field.substr(0, d.field.size() - 1) + ": " + detail + ")";
}

FirstDifference bytes_difference(const std::string& topic, std::uint64_t index, std::size_t golden_bytes,
                                 std::size_t run_bytes) {
  return FirstDifference{topic,
                         false,
                         index,
                         "(message bytes)",
                         std::to_string(golden_bytes) + " bytes",
                         std::to_string(run_bytes) + " bytes",
                         "bytes differ"};
}

FirstDifference log_time_difference(const std::string& topic, bool has_step, std::uint64_t step,
                                    std::uint64_t golden_ns, std::uint64_t run_ns) {
  const double diff = static_cast<double>(run_ns) - static_cast<double>(golden_ns);
  return FirstDifference{topic,
                         has_step,
                         step,
                         "(log_time)",
                         std::to_string(golden_ns) + " ns",
                         std::to_string(run_ns) + " ns",
                         fmt_short(diff) + " ns"};
}

MetadataDifference header_difference(const std::string& what, const std::string& golden,
                                     const std::string& run) {
  return {"MCAP header, " + what, "\"" + golden + "\"", "\"" + run + "\""};
}

MetadataDifference metadata_difference(const std::string& topic, const std::string& path,
                                       const msgs::Scalar& golden, const msgs::Scalar& run) {
  return {topic + ", field " + path, value_text(golden), value_text(run)};
}

std::string MetadataDifference::line() const {
  return where + ": expected " + expected + ", actual " + actual;
}

std::string FirstDifference::line() const {
  if (topic_level && topic.empty()) return field.substr(1, field.size() - 2);
  if (topic_level) return "topic " + topic + ": " + field.substr(1, field.size() - 2);
  std::string out = "topic " + topic + ", " + (has_step ? "step " : "message ") + std::to_string(step);
  if (!field.empty() && field.front() == '(' && expected.empty())
    return out + ": " + field.substr(1, field.size() - 2);
  out += ", field " + field + ": expected " + expected + ", actual " + actual + ", difference " + difference;
  return out;
}

// ---------------------------------------------------------------------------------------------
// The report.

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
         plural(r.topics.size(), "", "s"), static_cast<unsigned long long>(r.messages),
         plural(r.messages, "", "s"), g(mb).c_str());
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
