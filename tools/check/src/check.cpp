// Golden-log checks: two recordings compared message by message and field by field.
//
// Both files are streamed once, side by side (mcap::StreamReader, every CRC verified), so memory
// stays bounded by the chunks in flight plus the messages one file is ahead of the other. Each
// message pair is decoded into reused Scalar vectors; a "plan" mapping every scalar to its field
// group (the path with indices collapsed) is computed once per message layout and reused while
// sequence lengths stay the same, so the per-value loop allocates nothing and builds no strings.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <filesystem>
#include <limits>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <sstream>
#include <thread>
#include <tuple>
#include <utility>

#include "layout.hpp"
#include "rbsim/assert.hpp"
#include "rbsim/check.hpp"
#include "rbsim/mcap.hpp"
#include "record_pump.hpp"

namespace rbsim::check {

namespace {

using msgs::Scalar;
using Kind = Scalar::Kind;

constexpr int kRun = 0;
constexpr int kGolden = 1;
// Messages one file may be ahead of the other on a topic before we give up (memory bound).
constexpr std::uint64_t kMaxQueuedBytes = std::uint64_t{1} << 30;

std::span<const std::byte> cdr(const mcap::Bytes& b) {
  return std::as_bytes(std::span<const std::uint8_t>(b));
}
std::string fmt_short(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

// A value as the report shows it: floats in shortest round-trip form.
std::string text(const Scalar& s) {
  if (s.kind != Kind::Float) return s.to_string();
  char buf[40];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, s.f, std::chars_format::general);  // shortest
  return ec == std::errc() ? std::string(buf, end) : s.to_string();
}

std::uint64_t step_value(const Scalar& s) {
  return s.kind == Kind::Int ? static_cast<std::uint64_t>(s.i) : s.u;
}

const char* kind_label(Kind k) {
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

// "1,000"
std::string grouped(std::uint64_t n) {
  std::string digits = std::to_string(n), out;
  for (std::size_t i = 0; i < digits.size(); ++i) {
    if (i > 0 && (digits.size() - i) % 3 == 0) out += ',';
    out += digits[i];
  }
  return out;
}

// "2nd", "10th"
std::string ordinal(std::uint64_t n) {
  const std::uint64_t tens = n % 100, ones = n % 10;
  const char* suffix = (tens >= 11 && tens <= 13) ? "th"
                       : ones == 1                ? "st"
                       : ones == 2                ? "nd"
                       : ones == 3                ? "rd"
                                                  : "th";
  return std::to_string(n) + suffix;
}

// The steps a topic has in one file only, as arithmetic runs: "0..999", "5, 15, ..., 995".
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
  std::string text() const {
    std::string out;
    for (const Run& r : runs) {
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
    if (more_runs > 0) out += " and more";
    return out;
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

struct Stat {
  std::uint64_t values = 0, over = 0;
  double max_abs = 0.0, max_rel = 0.0;
  std::uint64_t step_at_max = 0;
};

struct SideInfo {
  bool has = false;
  std::string schema_name, schema_encoding, message_encoding;
  mcap::Bytes schema_data;
};

struct Topic {
  std::string name;
  bool selected = true;
  SideInfo side[2];
  bool ready = false;
  enum class Mode : std::uint8_t { Fields, Bytes, Skip } mode = Mode::Skip;
  std::optional<msgs::MessageDecoder> decoder[2];
  std::optional<Layout> layout;
  std::vector<Stat> stats;  // one per layout group, then "(bytes)" / "(log_time)"
  std::size_t bytes_stat = 0, time_stat = 0;
  std::deque<Pending> queue[2];
  std::uint64_t queued_bytes = 0;
  std::uint64_t count[2] = {0, 0};
  std::vector<std::uint64_t> identical_counts;  // values of byte-identical message pairs, per group
  bool diverged_message = false;                // scratch: current message pair has a difference
  // Per-step topics of rbsim's types pair up by simulated step (both files have a dt).
  std::optional<msgs::TopicId> step_id;
  bool aligned = false;
  StepTrack track[2];
  StepRuns only[2];  // steps in this file only
  // Metadata groups (the scene description's name, description, viewport, background).
  bool has_meta = false;
  std::vector<char> meta;
  std::vector<char> meta_reported;
};

struct Side {
  std::string path, role;  // role: "run" or "golden"
  RecordPump pump;
  std::map<std::uint16_t, mcap::Schema> schemas;
  std::map<std::uint16_t, std::size_t> channel_topic;
  std::set<std::string> summary_topics;
  bool summary_known = false;  // the summary lists every channel with messages
  std::uint64_t ordinal = 0, bytes = 0, consumed = 0;
  bool done = false;
  double dt = 0.0;  // from the first scene description (0: none, messages pair by position)
  std::optional<msgs::SceneMessage> scene;  // the first scene description, when it decodes
  mcap::Header header;
};

// Why two scene descriptions are not the same scene, or "" when they are: a different structure
// (bodies, hull vertex counts, which bodies each spring joins, force fields, integrator). Values
// (masses, vertex positions, stiffnesses, dt) are left to the field comparison and its tolerance:
// a perturbed run of the same scene is compared value by value.
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

std::string with_path(const Side& s, const std::string& what) {
  return s.role + " log " + s.path + ": " + what;
}

class Comparer {
 public:
  Comparer(const CheckOptions& options, const std::string& run, const std::string& golden) : o_(options) {
    side_[kRun].path = run;
    side_[kRun].role = "run";
    side_[kGolden].path = golden;
    side_[kGolden].role = "golden";
  }

  Result<CheckReport> compare() {
    if (!(o_.atol >= 0.0) || !(o_.rtol >= 0.0) || !std::isfinite(o_.atol) || !std::isfinite(o_.rtol)) {
      return Error{"--atol and --rtol must be finite and >= 0"};
    }
    for (int s : {kGolden, kRun}) {
      if (Status st = open(side_[s]); !st) return st.error();
    }
    const mcap::Header& hr = side_[kRun].header;
    const mcap::Header& hg = side_[kGolden].header;
    for (auto [what, run, golden] :
         {std::tuple{"profile", &hr.profile, &hg.profile}, std::tuple{"library", &hr.library, &hg.library}}) {
      if (*run == *golden) continue;
      report_.metadata.push_back(
          {std::string("MCAP header, ") + what, "\"" + *golden + "\"", "\"" + *run + "\""});
      if (o_.strict_metadata) {
        FirstDifference d;
        d.topic_level = true;
        d.field = "(" + report_.metadata.back().line() + ")";
        consider(Key{0, problem_ordinal_++}, std::move(d));
      }
    }
    if (side_[kRun].scene && side_[kGolden].scene) {
      // Recordings of two different scenes differ in nearly every value; one line says why.
      const std::string why = scene_difference(*side_[kGolden].scene, *side_[kRun].scene);
      if (!why.empty()) {
        report_.scene_mismatch = "the run and the golden record different scenes (golden " +
                                 quoted(side_[kGolden].scene->name) + ", run " +
                                 quoted(side_[kRun].scene->name) + "): " + why;
        FirstDifference d;
        d.topic_level = true;
        d.field = "(" + report_.scene_mismatch + ")";
        consider(Key{0, problem_ordinal_++}, std::move(d));
        return std::move(report_);
      }
    }
    while (!side_[kRun].done || !side_[kGolden].done) {
      int s = kGolden;
      if (side_[kGolden].done) {
        s = kRun;
      } else if (!side_[kRun].done && side_[kRun].consumed < side_[kGolden].consumed) {
        s = kRun;
      }
      if (Status st = step(s); !st) return st.error();
    }
    return finish();
  }

 private:
  Status open(Side& s) {
    // The summary first: a clear error for a truncated or non-MCAP file before any comparing, and
    // the file's whole topic list (so messages of a topic the other file lacks are not queued).
    std::error_code ec;
    const auto status = std::filesystem::status(s.path, ec);
    if (std::filesystem::is_directory(status)) return Error{with_path(s, "is a directory, not an MCAP file")};
    if (std::filesystem::is_regular_file(status) && std::filesystem::file_size(s.path, ec) == 0 && !ec) {
      return Error{with_path(s, "empty file, not an MCAP file")};
    }
    mcap::IndexedReader index;
    if (auto st = index.open(s.path); !st.ok()) return Error{with_path(s, describe(st.error()))};
    s.header = index.header();
    for (const auto& [id, channel] : index.channels()) s.summary_topics.insert(channel.topic);
    if (Status st = read_dt(s, index); !st) return st;
    // The summary's channels are known to be complete when every chunk's message index names
    // only channels it lists (rbsim writes indexes and repeats channels; other writers may not).
    s.summary_known = index.indexed();
    for (const mcap::ChunkIndex& ci : index.chunk_indexes()) {
      if (ci.message_index_offsets.empty()) s.summary_known = false;
      for (const auto& [channel_id, offset] : ci.message_index_offsets) {
        if (index.channels().count(channel_id) == 0) s.summary_known = false;
      }
    }
    if (auto st = s.pump.open(s.path); !st.ok()) return Error{with_path(s, describe(st.error()))};
    return Ok{};
  }

  // The first scene description: its time step (steps are round(stamp / dt)) and, for the
  // different-scene check, the scene itself.
  static Status read_dt(Side& s, mcap::IndexedReader& index) {
    std::vector<std::string> scene_topics;
    for (const auto& [id, channel] : index.channels()) {
      const auto schema = index.schemas().find(channel.schema_id);
      if (schema != index.schemas().end() && is_type(schema->second.name, msgs::TopicId::Scene))
        scene_topics.push_back(channel.topic);
    }
    if (scene_topics.empty()) return Ok{};
    mcap::ReadMessagesOptions options;
    options.topics = scene_topics;
    const Status st = index.read_messages(options, [&](const mcap::MessageEntry& e) {
      Result<msgs::SceneMessage> scene = msgs::decode_scene(cdr(e.message.data));
      if (scene && std::isfinite(scene->dt) && scene->dt > 0.0) s.dt = scene->dt;
      if (scene) s.scene = std::move(scene.value());
      return false;
    });
    if (!st.ok()) return Error{with_path(s, describe(st.error()))};
    return Ok{};
  }

  static bool is_type(const std::string& schema_name, msgs::TopicId id) {
    return msgs::topic_for_type(schema_name) == &msgs::topic(id);
  }

  static std::string describe(const Error& st) {
    switch (st.code) {
      case ErrorCode::BadMagic:
        return st.message.starts_with("not an MCAP file") ? st.message
                                                          : "not an MCAP file (" + st.message + ")";
      case ErrorCode::Truncated:
        return "truncated or incomplete MCAP file (" + st.message + ")";
      case ErrorCode::CrcMismatch:
        return "corrupted MCAP file (" + st.message + ")";
      case ErrorCode::Malformed:
      case ErrorCode::DecompressionFailed:
        return "corrupted MCAP file (" + st.message + ")";
      default:
        return st.message;
    }
  }

  static bool any_names(const std::vector<std::string>& list, const std::string& topic) {
    return std::any_of(list.begin(), list.end(),
                       [&](const std::string& n) { return msgs::names_topic(n, topic); });
  }
  bool selected(const std::string& topic) const {
    if (any_names(o_.exclude_topics, topic)) return false;
    return o_.topics.empty() || any_names(o_.topics, topic);
  }

  Status step(int si) {
    Side& s = side_[si];
    mcap::Record* next = s.pump.next();
    if (next == nullptr) {
      if (!s.pump.status().ok()) return Error{with_path(s, describe(s.pump.status().error()))};
      s.done = true;
      return Ok{};
    }
    mcap::Record& record = *next;
    if (auto* schema = std::get_if<mcap::Schema>(&record)) {
      s.schemas.try_emplace(schema->id, std::move(*schema));
    } else if (auto* channel = std::get_if<mcap::Channel>(&record)) {
      return add_channel(si, *channel);
    } else if (auto* message = std::get_if<mcap::Message>(&record)) {
      return add_message(si, *message);
    }
    return Ok{};
  }

  Status add_channel(int si, const mcap::Channel& channel) {
    Side& s = side_[si];
    if (s.channel_topic.count(channel.id) != 0) return Ok{};  // the summary repeats channels
    auto [it, fresh] = topic_index_.try_emplace(channel.topic, topics_.size());
    if (fresh) {
      topics_.emplace_back();
      topics_.back().name = channel.topic;
      topics_.back().selected = selected(channel.topic);
    }
    s.channel_topic[channel.id] = it->second;
    Topic& t = topics_[it->second];
    SideInfo& info = t.side[si];
    if (info.has) return Ok{};  // a second channel on the topic: its messages join the first's
    info.has = true;
    info.message_encoding = channel.message_encoding;
    if (channel.schema_id != 0) {
      const auto sc = s.schemas.find(channel.schema_id);
      if (sc == s.schemas.end()) {
        return Error{with_path(s, "channel " + std::to_string(channel.id) + " (" + channel.topic +
                                      ") refers to schema " + std::to_string(channel.schema_id) +
                                      ", which the file does not define")};
      }
      info.schema_name = sc->second.name;
      info.schema_encoding = sc->second.encoding;
      info.schema_data = sc->second.data;
    }
    if (t.side[1 - si].has && t.selected) return setup(t);
    return Ok{};
  }

  // Both files define the topic: decide how its messages compare.
  Status setup(Topic& t) {
    t.ready = true;
    const SideInfo& r = t.side[kRun];
    const SideInfo& g = t.side[kGolden];
    auto problem = [&](const std::string& what) {
      t.mode = Topic::Mode::Skip;
      topic_problem(t, what);
      return Ok{};
    };
    if (r.schema_name != g.schema_name) {
      return problem("schema differs: golden " + quoted(g.schema_name) + ", run " + quoted(r.schema_name));
    }
    if (r.message_encoding != g.message_encoding || r.schema_encoding != g.schema_encoding) {
      return problem("encoding differs: golden " + g.message_encoding + "/" + g.schema_encoding + ", run " +
                     r.message_encoding + "/" + r.schema_encoding);
    }
    if (g.message_encoding == "cdr" && g.schema_encoding == "ros2msg") {
      for (int si : {kRun, kGolden}) {
        const SideInfo& info = t.side[si];
        const std::string_view text(reinterpret_cast<const char*>(info.schema_data.data()),
                                    info.schema_data.size());
        auto decoder = msgs::MessageDecoder::create(info.schema_name, text);
        if (!decoder) {
          return Error{with_path(
              side_[si], "schema " + info.schema_name + " of " + t.name + ": " + decoder.error().message)};
        }
        t.decoder[si] = std::move(decoder.value());
        auto layout = Layout::create(info.schema_name, text);
        if (!layout) {
          return Error{with_path(
              side_[si], "schema " + info.schema_name + " of " + t.name + ": " + layout.error().message)};
        }
        if (si == kRun) {
          t.layout = std::move(layout.value());
        } else if (!t.layout->same_fields(layout.value())) {
          return problem("schema " + g.schema_name + " defines different fields in the two files");
        }
      }
      t.mode = Topic::Mode::Fields;
      t.stats.resize(t.layout->groups().size() + 1);
      t.time_stat = t.layout->groups().size();
      if (const msgs::TopicSpec* spec = msgs::topic_for_type(g.schema_name);
          spec != nullptr && spec->per_step)
        t.step_id = spec->id;
      t.aligned = t.step_id.has_value() && side_[kRun].dt > 0.0 && side_[kGolden].dt > 0.0;
      if (t.aligned) {
        // Messages queued before the other file defined the topic get their steps now.
        for (int si : {kRun, kGolden}) {
          for (Pending& p : t.queue[si]) p.step = step_of_message(t, si, p.data);
        }
      }
      if (is_type(g.schema_name, msgs::TopicId::Scene)) {
        const auto& groups = t.layout->groups();
        t.meta.assign(groups.size(), 0);
        t.meta_reported.assign(groups.size(), 0);
        for (std::size_t gi = 0; gi < groups.size(); ++gi) {
          const std::string& path = groups[gi].path;
          if (path == "name" || path == "description" || path == "has_viewport" ||
              path.starts_with("viewport_") || path.starts_with("background.")) {
            t.meta[gi] = 1;
            t.has_meta = true;
          }
        }
      }
    } else {
      t.mode = Topic::Mode::Bytes;  // not ros2msg/CDR: the bytes must be equal
      t.stats.resize(2);
      t.bytes_stat = 0;
      t.time_stat = 1;
    }
    return Ok{};
  }

  static std::string quoted(const std::string& s) { return s.empty() ? "(none)" : "'" + s + "'"; }

  void topic_problem(const Topic& t, const std::string& what) {
    report_.topic_problems.push_back(t.name + ": " + what);
    FirstDifference d;
    d.topic = t.name;
    d.topic_level = true;
    d.field = "(" + what + ")";
    consider(Key{0, problem_ordinal_++}, std::move(d));
  }

  // True when `d` became the first divergence.
  bool consider(Key key, FirstDifference d) {
    if (!report_.first || key < first_key_) {
      first_key_ = key;
      report_.first = std::move(d);
      first_only_.reset();
      return true;
    }
    return false;
  }

  // The simulated step of a per-step message: round(stamp / dt) with the file's own dt (a message
  // without a stamp, an empty MarkerArray, follows the previous one).
  std::uint64_t step_of_message(Topic& t, int si, const mcap::Bytes& data) {
    StepTrack& tr = t.track[si];
    std::uint64_t step = tr.any ? tr.last + std::max<std::uint64_t>(tr.stride, 1) : 0;
    if (const auto stamp = msgs::decode_stamp(*t.step_id, cdr(data))) {
      const double ns = static_cast<double>(stamp->sec) * 1e9 + static_cast<double>(stamp->nanosec);
      const double k = std::round(ns / (side_[si].dt * 1e9));
      step = !(k > 0.0) ? 0 : k >= 1.8e19 ? UINT64_MAX : static_cast<std::uint64_t>(k);
    }
    tr.add(step);
    return step;
  }

  // A message whose step the other file lacks.
  void only(Topic& t, int si, const Pending& p) {
    t.only[si].add(p.step);
    ++report_.diverging_messages;
    ++report_.one_file_messages;
    FirstDifference d{
        t.name, true, p.step, si == kGolden ? "(message missing from the run)" : "(extra message in the run)",
        "",     "",   ""};
    if (consider(Key{p.log_time, p.ordinal}, std::move(d))) {
      first_only_ = std::pair{static_cast<std::size_t>(&t - topics_.data()), si};
    }
  }

  // "run lacks steps 0..999 (1,000 messages: recorder joined late?)"
  std::string only_summary(const Topic& t, int si) const {
    const StepRuns& runs = t.only[si];
    const StepTrack& r = t.track[kRun];
    const StepTrack& g = t.track[kGolden];
    std::string out = std::string(si == kGolden ? "run lacks steps " : "run has extra steps ") + runs.text() +
                      " (" + grouped(runs.count) + (runs.count == 1 ? " message" : " messages");
    std::vector<std::string> hints;
    if (r.stride != 0 && g.stride != 0 && r.stride != g.stride) {
      hints.push_back("golden recorded " +
                      (g.stride == 1 ? "every step" : "every " + ordinal(g.stride) + " step") + ", run " +
                      (r.stride == 1 ? "every step" : "every " + ordinal(r.stride)) + " (--record-every)");
    } else if (!runs.runs.empty()) {
      const StepTrack& mine = si == kGolden ? g : r;
      const StepTrack& other = si == kGolden ? r : g;
      const bool leading = runs.runs.front().first == mine.first && other.any && mine.first < other.first;
      const bool trailing = runs.runs.back().last == mine.last && other.any && mine.last > other.last;
      if (si == kGolden) {
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

  // A metadata value pair that differs: reported once per field; true when it does not count as
  // a divergence (without strict_metadata).
  bool metadata(Topic& t, std::uint32_t group, std::uint64_t index, const Scalar& run, const Scalar& golden,
                std::span<const std::byte> golden_cdr) {
    if (!t.meta[group]) return false;
    if (!t.meta_reported[group]) {
      t.meta_reported[group] = 1;
      report_.metadata.push_back(
          {t.name + ", field " + t.decoder[kGolden]->path(golden_cdr, index), text(golden), text(run)});
    }
    return !o_.strict_metadata;
  }

  // A file ends its topic while the other still has messages; or the other never had the topic.
  bool other_lacks(const Topic& t, int si) const {
    const Side& o = side_[1 - si];
    return !t.side[1 - si].has && (o.done || (o.summary_known && o.summary_topics.count(t.name) == 0));
  }

  Status add_message(int si, mcap::Message& m) {
    Side& s = side_[si];
    const auto ch = s.channel_topic.find(m.channel_id);
    if (ch == s.channel_topic.end()) {
      return Error{with_path(s, "message on channel " + std::to_string(m.channel_id) +
                                    ", which the file does not define before it")};
    }
    s.bytes += m.data.size();
    const std::uint64_t ordinal = s.ordinal++;
    Topic& t = topics_[ch->second];
    if (!t.selected) return Ok{};
    const std::uint64_t index = t.count[si]++;
    ++s.consumed;
    if (other_lacks(t, si) || (t.ready && t.mode == Topic::Mode::Skip)) return Ok{};
    Pending p{std::move(m.data), m.log_time, ordinal, index};
    std::deque<Pending>& other = t.queue[1 - si];
    if (t.aligned) {
      // Pair by step: the other file's queued messages before this step are in that file only;
      // a message whose step the other file has passed is in this file only.
      p.step = step_of_message(t, si, p.data);
      while (!other.empty() && other.front().step < p.step) {
        only(t, 1 - si, other.front());
        t.queued_bytes -= other.front().data.size();
        other.pop_front();
      }
      if (!other.empty() && other.front().step > p.step) {
        only(t, si, p);
        return Ok{};
      }
    }
    if (!other.empty()) {
      Pending& q = other.front();
      Status st = si == kRun ? compare(t, p, q) : compare(t, q, p);
      t.queued_bytes -= q.data.size();
      side_[si].pump.recycle(std::move(p.data));
      side_[1 - si].pump.recycle(std::move(q.data));
      other.pop_front();
      return st;
    }
    t.queued_bytes += p.data.size();
    if (t.queued_bytes > kMaxQueuedBytes) {
      return Error{"the two logs are too far out of step on " + t.name + " to compare (over " +
                   std::to_string(kMaxQueuedBytes >> 20) + " MiB of messages in one file without a partner)"};
    }
    t.queue[si].push_back(std::move(p));
    return Ok{};
  }

  // One message pair: `r` from the run, `g` from the golden.
  Status compare(Topic& t, const Pending& r, const Pending& g) {
    ++report_.messages;
    last_has_step_ = t.aligned;
    last_step_ = t.aligned ? g.step : g.index;
    t.diverged_message = false;
    const Key key{g.log_time, g.ordinal};
    if (t.mode == Topic::Mode::Bytes) {
      const bool equal = r.data == g.data;
      Stat& st = t.stats[t.bytes_stat];
      ++st.values;
      if (!equal) {
        ++st.over;
        ++report_.diverging_values;
        t.diverged_message = true;
        if (st.max_abs < 1.0) {
          st.max_abs = 1.0;
          st.max_rel = 1.0;
          st.step_at_max = g.index;
        }
        if (!report_.first || key < first_key_) {
          FirstDifference d{t.name,
                            false,
                            g.index,
                            "(message bytes)",
                            std::to_string(g.data.size()) + " bytes",
                            std::to_string(r.data.size()) + " bytes",
                            "bytes differ"};
          consider(key, std::move(d));
        }
      }
    } else if (r.data == g.data && t.layout->count(cdr(g.data), t.identical_counts)) {
      // Byte-identical messages: every value matches exactly; only count them per field.
    } else {
      if (Status st = compare_fields(t, r, g, key); !st) return st;
    }
    if (o_.compare_log_time) compare_time(t, r, g, key);
    if (t.diverged_message) ++report_.diverging_messages;
    return Ok{};
  }

  void compare_time(Topic& t, const Pending& r, const Pending& g, Key key) {
    Stat& st = t.stats[t.time_stat];
    ++st.values;
    if (r.log_time == g.log_time) return;
    const double diff = static_cast<double>(r.log_time) - static_cast<double>(g.log_time);
    ++st.over;
    ++report_.diverging_values;
    if (std::fabs(diff) > st.max_abs) {
      st.max_abs = std::fabs(diff);
      st.max_rel = g.log_time == 0 ? std::numeric_limits<double>::infinity()
                                   : st.max_abs / static_cast<double>(g.log_time);
      st.step_at_max = last_step_;
    }
    if (!t.diverged_message) {
      t.diverged_message = true;
      if (!report_.first || key < first_key_) {
        FirstDifference d{t.name,
                          last_has_step_,
                          last_step_,
                          "(log_time)",
                          std::to_string(g.log_time) + " ns",
                          std::to_string(r.log_time) + " ns",
                          fmt_short(diff) + " ns"};
        consider(key, std::move(d));
      }
    }
  }

  Status decode(Topic& t, int si, const Pending& p, std::vector<Scalar>& out) {
    if (Status st = t.decoder[si]->decode(cdr(p.data), out); !st) {
      return Error{
          with_path(side_[si], t.name + " message " + std::to_string(p.index) + ": " + st.error().message)};
    }
    return Ok{};
  }

  // Walks a run message (a) and a golden message (b) in lockstep straight from their CDR bytes
  // (the decoder's rules: XCDR1, little endian, alignment relative to the end of the 4-byte
  // header), comparing every value as it goes. Stops at the first differing sequence length
  // (the layouts part) or at data that does not fit the schema; `index` then counts the values
  // compared, in the decoder's scalar order.
  enum class Walk : std::uint8_t { Ok, Mismatch, Malformed };
  struct Lockstep {
    Comparer& c;
    Topic& t;
    std::span<const std::byte> a, b;
    std::size_t pa = 4, pb = 4;
    std::uint64_t index = 0;
    std::uint64_t first_bad = UINT64_MAX;
    Scalar bad_a{}, bad_b{};  // the values at first_bad (run, golden), for the divergence report
    bool has_step = false;
    std::uint64_t step = 0;
    std::uint64_t budget = 0;

    static bool align(std::span<const std::byte> d, std::size_t& pos, std::size_t size, std::uint64_t n) {
      const std::size_t pad = (size - (pos - 4) % size) % size;
      const std::size_t left = d.size() - pos;
      if (pad > left || n > (left - pad) / size) return false;
      pos += pad;
      return true;
    }
    static std::uint32_t u32(const std::byte* p) {
      std::uint32_t v;
      std::memcpy(&v, p, 4);
      return v;
    }
    static Scalar load(const std::byte* p, std::uint8_t size, Kind kind) {
      return msgs::load_scalar(p, size, kind);
    }
    // Bit-equal values (floats: equal as numbers, so 0 == -0), the common case and the only one
    // that needs no more work than counting. Pairs that fail this go to mismatch().
    static bool same(const std::byte* x, const std::byte* y, std::uint8_t size, Kind kind) {
      if (kind == Kind::Float) {
        if (size == 8) {
          double va, vb;
          std::memcpy(&va, x, 8);
          std::memcpy(&vb, y, 8);
          return va == vb;
        }
        float fa, fb;
        std::memcpy(&fa, x, 4);
        std::memcpy(&fb, y, 4);
        return fa == fb;
      }
      switch (size) {
        case 1:
          return *x == *y;
        case 2: {
          std::uint16_t va, vb;
          std::memcpy(&va, x, 2);
          std::memcpy(&vb, y, 2);
          return va == vb;
        }
        case 4:
          return u32(x) == u32(y);
        case 8: {
          std::uint64_t va, vb;
          std::memcpy(&va, x, 8);
          std::memcpy(&vb, y, 8);
          return va == vb;
        }
        default:
          return std::memcmp(x, y, size) == 0;
      }
    }
    // One value pair at x (run) and y (golden): counted, compared, `index` advanced.
    void value(const std::byte* x, const std::byte* y, std::uint8_t size, Kind kind, std::uint32_t group) {
      ++t.stats[group].values;
      if (!same(x, y, size, kind)) mismatch(x, y, size, kind, group);
      ++index;
    }
    // mismatch() for float64 values va != vb at x and y, inline: the hot case of a check in which
    // every value moved (another compiler or machine, compared with a tolerance).
    void float_mismatch(const std::byte* x, const std::byte* y, double va, double vb, std::uint32_t group,
                        std::uint64_t at) {
      if (va != va && vb != vb) return;
      index = at;
      if (t.has_meta) return mismatch(x, y, 8, Kind::Float, group);
      if (!c.differs_float(t.stats[group], va, vb) && first_bad == UINT64_MAX)
        mark(float_scalar(va), float_scalar(vb));
    }
    // A value pair (value number `index`, already counted) that same() found not equal: NaN pairs
    // match, metadata is reported apart, anything else is a difference (within the tolerance or not).
    [[gnu::noinline]] void mismatch(const std::byte* x, const std::byte* y, std::uint8_t size, Kind kind,
                                    std::uint32_t group) {
      Stat& st = t.stats[group];
      if (kind == Kind::Float) {
        double va, vb;
        if (size == 8) {
          std::memcpy(&va, x, 8);
          std::memcpy(&vb, y, 8);
        } else {
          float fa, fb;
          std::memcpy(&fa, x, 4);
          std::memcpy(&fb, y, 4);
          va = fa;
          vb = fb;
        }
        if (!(va == vb || (va != va && vb != vb)) &&
            !(t.has_meta && c.metadata(t, group, index, float_scalar(va), float_scalar(vb), b)) &&
            !c.differs_float(st, va, vb) && first_bad == UINT64_MAX) {
          mark(float_scalar(va), float_scalar(vb));
        }
        return;
      }
      const Scalar sa = load(x, size, kind), sb = load(y, size, kind);
      if (!(t.has_meta && c.metadata(t, group, index, sa, sb, b)) && !c.differs(st, sa, sb) &&
          first_bad == UINT64_MAX) {
        mark(sa, sb);
      }
    }
    static Scalar float_scalar(double v) {
      Scalar s;
      s.kind = Kind::Float;
      s.f = v;
      return s;
    }
    void mark(const Scalar& run_value, const Scalar& golden_value) {
      first_bad = index;
      bad_a = run_value;
      bad_b = golden_value;
    }
    Walk fields(const std::vector<Layout::Field>& fs, bool root) {
      using Array = Layout::Field::Array;
      for (const Layout::Field& f : fs) {
        std::uint64_t count = 1;
        if (f.array == Array::Sequence) {
          if (!align(a, pa, 4, 1) || !align(b, pb, 4, 1)) return Walk::Malformed;
          const std::uint32_t na = u32(a.data() + pa), nb = u32(b.data() + pb);
          pa += 4;
          pb += 4;
          if (na > a.size() - pa || nb > b.size() - pb) return Walk::Malformed;
          if (na != nb) {
            pa -= 4;
            pb -= 4;
            return Walk::Mismatch;
          }
          ++t.stats[f.length_group].values;
          ++index;
          count = na;
        } else if (f.array == Array::Fixed) {
          count = f.fixed;
        }
        if (count > budget) return Walk::Malformed;
        budget -= count;
        if (f.primitive && f.size > 0) {
          if (count == 0) continue;
          if (!align(a, pa, f.size, count) || !align(b, pb, f.size, count)) return Walk::Malformed;
          if (root && f.array == Array::None && f.name == "step") {
            has_step = true;
            step = step_value(load(b.data() + pb, f.size, f.kind));
          }
          t.stats[f.group].values += count;
          for (std::uint64_t k = 0; k < count; ++k, pa += f.size, pb += f.size, ++index) {
            if (!same(a.data() + pa, b.data() + pb, f.size, f.kind))
              mismatch(a.data() + pa, b.data() + pb, f.size, f.kind, f.group);
          }
        } else if (f.primitive) {  // strings
          for (std::uint64_t k = 0; k < count; ++k) {
            if (!align(a, pa, 4, 1) || !align(b, pb, 4, 1)) return Walk::Malformed;
            const std::uint32_t na = u32(a.data() + pa), nb = u32(b.data() + pb);
            pa += 4;
            pb += 4;
            if (na == 0 || nb == 0 || na > a.size() - pa || nb > b.size() - pb) return Walk::Malformed;
            Stat& st = t.stats[f.group];
            ++st.values;
            const std::string_view sa(reinterpret_cast<const char*>(a.data() + pa), na - 1);
            const std::string_view sb(reinterpret_cast<const char*>(b.data() + pb), nb - 1);
            if (sa != sb) {
              Scalar x, y;
              x.kind = y.kind = Kind::String;
              x.s = sa;
              y.s = sb;
              if (!(t.has_meta && c.metadata(t, f.group, index, x, y, b)) && !c.differs(st, x, y) &&
                  first_bad == UINT64_MAX) {
                mark(x, y);
              }
            }
            ++index;
            pa += na;
            pb += nb;
          }
        } else if (f.flat) {
          // The hot loop of a large message (bodies[], springs[]): values are counted per element
          // after the loop (flat_groups), each pair is tested for equality inline.
          std::uint64_t k = 0;
          Walk w = Walk::Ok;
          std::uint64_t at = index;  // the value number, kept out of memory in the loop
          // differs_float() spelled out for float64 pairs outside metadata: one NaN test on the
          // difference (NaN only when either value is NaN, as va != vb), the tolerance in locals.
          const bool plain = !t.has_meta;
          const double atol = c.o_.atol, rtol = c.o_.rtol;
          Stat* const stats = t.stats.data();
          for (; k < count; ++k) {
            const std::size_t ra = (pa - 4) % 8, rb = (pb - 4) % 8;
            if (f.flat_size[ra] > a.size() - pa || f.flat_size[rb] > b.size() - pb) {
              w = Walk::Malformed;
              break;
            }
            const Layout::Op* ops_a = f.flat_ops[ra].data();
            const Layout::Op* ops_b = f.flat_ops[rb].data();
            const std::size_t n = f.flat_ops[rb].size();
            const std::byte* xa = a.data() + pa;
            const std::byte* yb = b.data() + pb;
            for (std::size_t o = 0; o < n; ++o) {
              const Layout::Op& op = ops_b[o];
              const std::byte* x = xa + ops_a[o].offset;
              const std::byte* y = yb + op.offset;
              if (op.kind == Kind::Float && op.size == 8) {
                double va, vb;
                std::memcpy(&va, x, 8);
                std::memcpy(&vb, y, 8);
                if (va == vb) continue;
                if (!plain) {
                  float_mismatch(x, y, va, vb, op.group, at + o);
                  continue;
                }
                double d = std::fabs(va - vb);
                if (d != d) {
                  if (va != va && vb != vb) continue;  // both NaN: a match
                  d = std::numeric_limits<double>::infinity();
                }
                const double ab = std::fabs(vb);
                const double rel = vb != 0.0 ? d / ab : std::numeric_limits<double>::infinity();
                if (!c.record(stats[op.group], d, rel, d <= atol + rtol * ab) && first_bad == UINT64_MAX) {
                  index = at + o;
                  mark(float_scalar(va), float_scalar(vb));
                }
              } else if (!same(x, y, op.size, op.kind)) {
                index = at + o;
                mismatch(x, y, op.size, op.kind, op.group);
              }
            }
            at += n;
            pa += f.flat_size[ra];
            pb += f.flat_size[rb];
          }
          index = at;
          for (const auto& [g, n] : f.flat_groups) t.stats[g].values += n * k;
          if (w != Walk::Ok) return w;
        } else {
          for (std::uint64_t k = 0; k < count; ++k) {
            if (const Walk w = fields(f.children, false); w != Walk::Ok) return w;
          }
        }
      }
      return Walk::Ok;
    }
  };

  Status compare_fields(Topic& t, const Pending& r, const Pending& g, Key key) {
    touched_.clear();
    step_known_ = false;
    Lockstep ls{*this, t, cdr(r.data), cdr(g.data)};
    ls.budget = 4 * static_cast<std::uint64_t>(r.data.size() + g.data.size()) + 1024;
    Walk walk = Walk::Malformed;
    if (r.data.size() >= 4 && g.data.size() >= 4 && r.data[0] == 0 && r.data[1] == 1 && g.data[0] == 0 &&
        g.data[1] == 1) {
      walk = ls.fields(t.layout->root(), true);
    }
    const bool has_step = t.aligned || ls.has_step;
    const std::uint64_t step = t.aligned ? g.step : ls.has_step ? ls.step : g.index;
    for (Stat* st : touched_) st->step_at_max = step;
    step_known_ = true;
    cur_step_ = step;
    last_has_step_ = has_step;
    last_step_ = step;
    std::uint64_t first_bad = ls.first_bad, first_bad_run = ls.first_bad;
    bool decoded = false;
    if (walk != Walk::Ok) {
      // Sequence lengths differ (or the data is bad): decode both, which reports bad data, and
      // pair the values the two have in common past those already compared.
      if (Status st = decode(t, kRun, r, run_); !st) return st;
      if (Status st = decode(t, kGolden, g, golden_); !st) return st;
      decoded = true;
      if (!t.layout->pair(run_, golden_, pairs_)) {
        return Error{with_path(side_[kRun],
                               t.name + " message " + std::to_string(r.index) + " does not fit its schema")};
      }
      for (const Pair& p : pairs_) {
        if (p.b < ls.index) continue;
        Stat& st = t.stats[p.group];
        ++st.values;
        if (t.has_meta && !(run_[p.a] == golden_[p.b]) &&
            metadata(t, p.group, p.b, run_[p.a], golden_[p.b], cdr(g.data))) {
          continue;
        }
        if (!same_scalar(st, run_[p.a], golden_[p.b]) && first_bad == UINT64_MAX) {
          first_bad = p.b;
          first_bad_run = p.a;
        }
      }
    }
    if (first_bad != UINT64_MAX) {
      t.diverged_message = true;
      if (!report_.first || key < first_key_) {
        // The walk kept the values it found first; a decoded pair has them by index.
        RBSIM_ASSERT(!decoded || (first_bad < golden_.size() && first_bad_run < run_.size()),
                     "a decoded pair's first difference indexes its values");
        const Scalar& a = decoded ? run_[first_bad_run] : ls.bad_a;
        const Scalar& b = decoded ? golden_[first_bad] : ls.bad_b;
        FirstDifference d{
            t.name,  has_step,        step, t.decoder[kGolden]->path(cdr(g.data), first_bad), text(b),
            text(a), difference(a, b)};
        consider(key, std::move(d));
      }
    }
    return Ok{};
  }

  static std::string difference(const Scalar& a, const Scalar& b) {
    switch (b.kind) {
      case Kind::Float:
        return fmt_short(a.f - b.f);
      case Kind::Int:
        return std::to_string(static_cast<long long>(a.i) - static_cast<long long>(b.i));
      case Kind::UInt:
      case Kind::Length:
        return a.u >= b.u ? std::to_string(a.u - b.u) : "-" + std::to_string(b.u - a.u);
      case Kind::Bool:
      case Kind::String:
        return "differs";
    }
    return "differs";
  }

  bool same_scalar(Stat& st, const Scalar& a, const Scalar& b) {
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
  bool differs(Stat& st, const Scalar& a, const Scalar& b) {
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

  // Inlined into the flat-element loop (GCC otherwise calls it there, at twice the cost).
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
      ++report_.diverging_values;
    }
    return ok;
  }

  // The step of a leftover message, for the missing/extra report.
  std::pair<bool, std::uint64_t> step_of(Topic& t, int si, const Pending& p) {
    if (t.mode != Topic::Mode::Fields) return {false, p.index};
    std::vector<Scalar>& scratch = si == kRun ? run_ : golden_;
    if (!t.decoder[si]->decode(cdr(p.data), scratch)) return {false, p.index};
    Plan plan;
    if (!t.layout->map(scratch, plan) || plan.step < 0) return {false, p.index};
    return {true, step_value(scratch[static_cast<std::size_t>(plan.step)])};
  }

  Result<CheckReport> finish() {
    for (const std::string& name : o_.topics) {
      if (std::none_of(topics_.begin(), topics_.end(),
                       [&](const Topic& t) { return msgs::names_topic(name, t.name); })) {
        std::string known;
        for (const Topic& t : topics_) known += (known.empty() ? "" : ", ") + t.name;
        return Error{"--topics: " + name + " is in neither log (topics: " + (known.empty() ? "none" : known) +
                     ")"};
      }
    }
    std::vector<std::size_t> order(topics_.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::sort(order.begin(), order.end(),
              [&](std::size_t a, std::size_t b) { return topics_[a].name < topics_[b].name; });
    for (std::size_t i : order) {
      Topic& t = topics_[i];
      if (!t.selected) continue;
      for (int si : {kRun, kGolden}) {
        if (t.side[si].has && !t.side[1 - si].has) {
          topic_problem(
              t, "topic only in the " + side_[si].role + " (" + std::to_string(t.count[si]) + " messages)");
          report_.diverging_messages += t.count[si];
        }
      }
      if (!t.side[kRun].has || !t.side[kGolden].has) continue;
      report_.topics.push_back(t.name);
      if (t.aligned) {
        for (int si : {kRun, kGolden}) {
          for (const Pending& p : t.queue[si]) only(t, si, p);
          t.queue[si].clear();
        }
        for (int si : {kGolden, kRun}) {
          if (t.only[si].count > 0) report_.step_problems.push_back(t.name + ": " + only_summary(t, si));
        }
      }
      for (int si : {kRun, kGolden}) {
        if (t.queue[si].empty()) continue;
        const Pending& p = t.queue[si].front();
        const auto [has_step, step] = step_of(t, si, p);
        const std::string what =
            si == kGolden
                ? "message missing from the run: the golden has " + std::to_string(t.count[kGolden]) +
                      " messages on this topic, the run " + std::to_string(t.count[kRun])
                : "extra message in the run: the run has " + std::to_string(t.count[kRun]) +
                      " messages on this topic, the golden " + std::to_string(t.count[kGolden]);
        FirstDifference d{t.name, has_step, step, "(" + what + ")", "", "", ""};
        consider(Key{p.log_time, p.ordinal}, std::move(d));
        report_.diverging_messages += t.queue[si].size();
      }
      if (t.mode == Topic::Mode::Skip) continue;
      auto row = [&](const std::string& field, const std::string& kind, const Stat& st, bool has_step) {
        FieldStats f;
        f.topic = t.name;
        f.field = field;
        f.kind = kind;
        f.values = st.values;
        f.over = st.over;
        f.max_abs = st.max_abs;
        f.max_rel = st.max_rel;
        f.has_step = has_step;
        f.step_at_max = st.step_at_max;
        report_.fields.push_back(std::move(f));
      };
      const bool has_step = t.aligned || (t.mode == Topic::Mode::Fields && t.layout->has_step());
      for (std::size_t gi = 0; gi < t.identical_counts.size(); ++gi)
        t.stats[gi].values += t.identical_counts[gi];
      if (t.mode == Topic::Mode::Fields) {
        const auto& groups = t.layout->groups();
        for (std::size_t gi = 0; gi < groups.size(); ++gi) {
          if (t.stats[gi].values > 0)
            row(groups[gi].path, kind_label(groups[gi].kind), t.stats[gi], has_step);
        }
      } else {
        row("(bytes)", "bytes", t.stats[t.bytes_stat], false);
      }
      row("(log_time)", "time", t.stats[t.time_stat], has_step);
    }
    if (first_only_ && report_.first) {
      const auto [ti, si] = *first_only_;
      std::string& field = report_.first->field;
      field = field.substr(0, field.size() - 1) + ": " + only_summary(topics_[ti], si) + ")";
    }
    report_.run_bytes = side_[kRun].bytes;
    report_.golden_bytes = side_[kGolden].bytes;
    return std::move(report_);
  }

  const CheckOptions& o_;
  Side side_[2];
  std::vector<Topic> topics_;  // std::vector<Topic>: indices stay valid; elements are moved only on growth
  std::map<std::string, std::size_t> topic_index_;
  std::vector<Scalar> run_, golden_;
  std::vector<Pair> pairs_;
  CheckReport report_;
  Key first_key_;
  std::uint64_t problem_ordinal_ = 0;
  bool last_has_step_ = false;
  std::uint64_t last_step_ = 0;
  // Stats whose maximum changed before the message's step was known (fixed up after the walk).
  std::vector<Stat*> touched_;
  bool step_known_ = false;
  std::uint64_t cur_step_ = 0;
  std::optional<std::pair<std::size_t, int>> first_only_;  // the first divergence is a step in one file only
};

}  // namespace

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

Result<CheckReport> check_logs(const std::string& run_path, const std::string& golden_path,
                               const CheckOptions& options) {
  Comparer c(options, run_path, golden_path);
  return c.compare();
}

}  // namespace rbsim::check
