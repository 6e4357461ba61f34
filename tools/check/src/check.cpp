// Golden-log checks: two recordings compared message by message and field by field.
//
// Both files are streamed once, side by side (mcap::StreamReader, every CRC verified), so memory
// stays bounded by the chunks in flight plus the messages one file is ahead of the other. Messages
// pair up here, by step or by position; each pair's values are compared straight from the CDR
// bytes by the lockstep walker (compare_values.cpp), which allocates nothing and builds no strings
// per value. Pairs whose sequence lengths differ are decoded into reused Scalar vectors and paired
// by the layout (layout.cpp). Every sentence of the report comes from report.cpp (sentences.hpp).
#include <algorithm>
#include <cmath>
#include <cstring>
#include <deque>
#include <filesystem>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <tuple>
#include <utility>

#include "compare_values.hpp"
#include "layout.hpp"
#include "rbsim/assert.hpp"
#include "rbsim/check.hpp"
#include "rbsim/mcap.hpp"
#include "rbsim/record_stream.hpp"
#include "rbsim/recording.hpp"
#include "sentences.hpp"
#include "steps.hpp"

namespace rbsim::check {

namespace {

using msgs::Scalar;

// Two messages with the same bytes, by memcmp: vector<std::byte>'s == goes through std::equal,
// which GCC 12's libstdc++ runs a byte at a time for an enum type (it turns only integers into
// memcmp): 40% of a check of identical 10,000-body recordings.
bool same_bytes(const mcap::Bytes& a, const mcap::Bytes& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size()) == 0);
}

constexpr int kRun = 0;
constexpr int kGolden = 1;
// Messages one file may be ahead of the other on a topic before we give up (memory bound).
constexpr std::uint64_t kMaxQueuedBytes = std::uint64_t{1} << 30;

struct SideInfo {
  bool has = false;
  std::string schema_name, schema_encoding, message_encoding;
  mcap::Bytes schema_data;
};

struct Topic {
  std::string name;
  const msgs::TopicSpec* spec = nullptr;  // of its first channel's type, when one of ours
  bool selected = true;
  SideInfo side[2];
  bool ready = false;
  enum class Mode : std::uint8_t { Fields, Bytes, Skip } mode = Mode::Skip;
  std::optional<msgs::MessageDecoder> decoder[2];
  std::optional<Layout> layout;
  Tally tally;  // a Stat per layout group, then "(bytes)" / "(log_time)"; the metadata groups
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
};

struct Side {
  std::string path, role;  // role: "run" or "golden"
  recordings::RecordStream pump;
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
      report_.metadata.push_back(header_difference(what, *golden, *run));
      if (o_.strict_metadata)
        consider(Key{0, problem_ordinal_++}, topic_difference("", report_.metadata.back().line()));
    }
    if (side_[kRun].scene && side_[kGolden].scene) {
      // Recordings of two different scenes differ in nearly every value; one line says why.
      const std::string why = scene_difference(*side_[kGolden].scene, *side_[kRun].scene);
      if (!why.empty()) {
        report_.scene_mismatch = different_scenes(*side_[kGolden].scene, *side_[kRun].scene, why);
        consider(Key{0, problem_ordinal_++}, topic_difference("", report_.scene_mismatch));
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
    auto recording =
        recordings::Recording::open(s.path, recordings::raw_options());  // any file, whatever it carries
    if (!recording) return with_context(s.role + " log ", recording.error());
    const recordings::Recording& r = *recording.value();
    s.header = r.header();
    for (const recordings::RecordedChannel& c : r.channels()) s.summary_topics.insert(c.channel->topic);
    // The summary's channels are known to be complete when every chunk's message index names
    // only channels it lists (rbsim writes indexes and repeats channels; other writers may not).
    s.summary_known = r.lists_every_channel();
    if (Status st = read_dt(s, *recording.value()); !st) return st;
    if (Status st = s.pump.open(s.path); !st) return with_context(s.role + " log ", st.error());
    return Ok{};
  }

  // The first scene description: its time step (the step of a message that carries only a stamp is
  // round(stamp / dt)) and, for the
  // different-scene check, the scene itself.
  static Status read_dt(Side& s, recordings::Recording& recording) {
    recordings::MessageFilter scenes;
    for (const recordings::RecordedChannel& c : recording.channels()) {
      if (c.spec != nullptr && c.spec->id == msgs::TopicId::SceneDescription)
        scenes.topics.push_back(c.channel->topic);
    }
    if (scenes.topics.empty()) return Ok{};
    const Status st = recording.read_messages(scenes, [&](const recordings::RecordedMessage& m) {
      Result<msgs::SceneMessage> scene = msgs::decode_scene(m.cdr());
      if (scene && std::isfinite(scene->dt) && scene->dt > 0.0) s.dt = scene->dt;
      if (scene) s.scene = std::move(scene.value());
      return false;
    });
    if (!st) return with_context(s.role + " log ", st.error());
    return Ok{};
  }

  static bool is_type(const std::string& schema_name, msgs::TopicId id) {
    return msgs::topic_for_type(schema_name) == &msgs::topic(id);
  }

  // --topics and --exclude-topics by msgs::selects_topic(), the rule of msgs::select_topics().
  static bool any_names(const std::vector<std::string>& list, const msgs::TopicCandidate& topic) {
    return std::any_of(list.begin(), list.end(),
                       [&](const std::string& n) { return msgs::selects_topic(n, topic); });
  }
  bool selected(const msgs::TopicCandidate& topic) const {
    if (any_names(o_.exclude_topics, topic)) return false;
    return o_.topics.empty() || any_names(o_.topics, topic);
  }

  Status step(int si) {
    Side& s = side_[si];
    mcap::Record* next = s.pump.next();
    if (next == nullptr) {
      if (Status st = s.pump.status(); !st) return with_context(s.role + " log ", st.error());
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
      const auto schema = s.schemas.find(channel.schema_id);
      topics_.emplace_back();
      topics_.back().name = channel.topic;
      topics_.back().spec = schema == s.schemas.end() ? nullptr : msgs::topic_for_type(schema->second.name);
      topics_.back().selected = selected({channel.topic, topics_.back().spec});
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
      return problem(schema_differs(g.schema_name, r.schema_name));
    }
    if (r.message_encoding != g.message_encoding || r.schema_encoding != g.schema_encoding) {
      return problem(
          encoding_differs(g.message_encoding, g.schema_encoding, r.message_encoding, r.schema_encoding));
    }
    if (g.message_encoding == "cdr" && g.schema_encoding == "ros2msg") {
      for (int si : {kRun, kGolden}) {
        const SideInfo& info = t.side[si];
        const std::string_view text(reinterpret_cast<const char*>(info.schema_data.data()),
                                    info.schema_data.size());
        auto decoder = msgs::MessageDecoder::create(info.schema_name, text);
        if (!decoder) {
          return with_context(with_path(side_[si], "schema " + info.schema_name + " of " + t.name + ": "),
                              decoder.error());
        }
        t.decoder[si] = std::move(decoder.value());
        auto layout = Layout::create(info.schema_name, text);
        if (!layout) {
          return with_context(with_path(side_[si], "schema " + info.schema_name + " of " + t.name + ": "),
                              layout.error());
        }
        if (si == kRun) {
          t.layout = std::move(layout.value());
        } else if (!t.layout->same_fields(layout.value())) {
          return problem(fields_differ(g.schema_name));
        }
      }
      t.mode = Topic::Mode::Fields;
      t.tally.stats.resize(t.layout->groups().size() + 1);
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
      const bool scene = is_type(g.schema_name, msgs::TopicId::SceneDescription);
      if (scene || is_type(g.schema_name, msgs::TopicId::Commands)) {
        const auto& groups = t.layout->groups();
        t.tally.meta.assign(groups.size(), 0);
        t.tally.meta_reported.assign(groups.size(), 0);
        for (std::size_t gi = 0; gi < groups.size(); ++gi) {
          const std::string& path = groups[gi].path;
          if (scene ? msgs::is_scene_metadata(path) : msgs::is_command_metadata(path)) {
            t.tally.meta[gi] = 1;
            t.tally.has_meta = true;
          }
        }
      }
    } else {
      t.mode = Topic::Mode::Bytes;  // not ros2msg/CDR: the bytes must be equal
      t.tally.stats.resize(2);
      t.bytes_stat = 0;
      t.time_stat = 1;
    }
    return Ok{};
  }

  void topic_problem(const Topic& t, const std::string& what) {
    report_.topic_problems.push_back(t.name + ": " + what);
    consider(Key{0, problem_ordinal_++}, topic_difference(t.name, what));
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

  // The simulated step of a per-step message, msgs::message_step with the file's own dt; a message
  // without one (an empty MarkerArray) follows the previous one.
  std::uint64_t step_of_message(Topic& t, int si, const mcap::Bytes& data) {
    StepTrack& tr = t.track[si];
    const std::uint64_t step = msgs::message_step(*t.step_id, data, side_[si].dt)
                                   .value_or(tr.any ? tr.last + std::max<std::uint64_t>(tr.stride, 1) : 0);
    tr.add(step);
    return step;
  }

  // A message whose step the other file lacks.
  void only(Topic& t, int si, const Pending& p) {
    t.only[si].add(p.step);
    ++report_.diverging_messages;
    ++report_.one_file_messages;
    if (consider(Key{p.log_time, p.ordinal},
                 message_difference(t.name, true, p.step, message_in_one_file(si == kGolden)))) {
      first_only_ = std::pair{static_cast<std::size_t>(&t - topics_.data()), si};
    }
  }

  // "run lacks steps 0..999 (1,000 messages: recorder joined late?)"
  std::string only_summary(const Topic& t, int si) const {
    return check::only_summary(t.only[si], si == kGolden, t.track[kRun], t.track[kGolden]);
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
      const bool equal = same_bytes(r.data, g.data);
      Stat& st = t.tally.stats[t.bytes_stat];
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
        if (!report_.first || key < first_key_)
          consider(key, bytes_difference(t.name, g.index, g.data.size(), r.data.size()));
      }
    } else if (same_bytes(r.data, g.data) && t.layout->count(g.data, t.identical_counts)) {
      // Byte-identical messages: every value matches exactly; only count them per field.
    } else {
      if (Status st = compare_fields(t, r, g, key); !st) return st;
    }
    if (o_.compare_log_time) compare_time(t, r, g, key);
    if (t.diverged_message) ++report_.diverging_messages;
    return Ok{};
  }

  void compare_time(Topic& t, const Pending& r, const Pending& g, Key key) {
    Stat& st = t.tally.stats[t.time_stat];
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
      if (!report_.first || key < first_key_)
        consider(key, log_time_difference(t.name, last_has_step_, last_step_, g.log_time, r.log_time));
    }
  }

  Status decode(Topic& t, int si, const Pending& p, std::vector<Scalar>& out) {
    if (Status st = t.decoder[si]->decode(p.data, out); !st) {
      return with_context(with_path(side_[si], t.name + " message " + std::to_string(p.index) + ": "),
                          st.error());
    }
    return Ok{};
  }

  Status compare_fields(Topic& t, const Pending& r, const Pending& g, Key key) {
    values_.begin_message();
    const WalkResult ls = lockstep(values_, *t.layout, t.tally, t.name, *t.decoder[kGolden], r.data, g.data);
    const bool has_step = t.aligned || ls.has_step;
    const std::uint64_t step = t.aligned ? g.step : ls.has_step ? ls.step : g.index;
    values_.at_step(step);
    last_has_step_ = has_step;
    last_step_ = step;
    std::uint64_t first_bad = ls.first_bad, first_bad_run = ls.first_bad;
    bool decoded = false;
    if (ls.walk != Walk::Ok) {
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
        Stat& st = t.tally.stats[p.group];
        ++st.values;
        if (t.tally.has_meta && !(run_[p.a] == golden_[p.b]) &&
            values_.metadata(t.tally, t.name, *t.decoder[kGolden], p.group, p.b, run_[p.a], golden_[p.b],
                             g.data)) {
          continue;
        }
        if (!values_.same_scalar(st, run_[p.a], golden_[p.b]) && first_bad == UINT64_MAX) {
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
            t.name,        has_step,        step, t.decoder[kGolden]->path(g.data, first_bad), value_text(b),
            value_text(a), difference(a, b)};
        consider(key, std::move(d));
      }
    }
    return Ok{};
  }

  // The step of a leftover message, for the missing/extra report.
  std::pair<bool, std::uint64_t> step_of(Topic& t, int si, const Pending& p) {
    if (t.mode != Topic::Mode::Fields) return {false, p.index};
    std::vector<Scalar>& scratch = si == kRun ? run_ : golden_;
    if (!t.decoder[si]->decode(p.data, scratch)) return {false, p.index};
    Plan plan;
    if (!t.layout->map(scratch, plan) || plan.step < 0) return {false, p.index};
    return {true, step_value(scratch[static_cast<std::size_t>(plan.step)])};
  }

  Result<CheckReport> finish() {
    {  // every --topics name selects a topic of either log
      std::vector<msgs::TopicCandidate> known;
      for (const Topic& t : topics_) known.push_back({t.name, t.spec});
      msgs::TopicFilter filter;
      filter.topics = o_.topics;
      if (Result<std::vector<std::size_t>> chosen = msgs::select_topics(filter, known); !chosen)
        return chosen.error();
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
          topic_problem(t, topic_only_in(side_[si].role, t.count[si]));
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
        const std::string what = messages_left_over(si == kGolden, t.count[kRun], t.count[kGolden]);
        consider(Key{p.log_time, p.ordinal}, message_difference(t.name, has_step, step, what));
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
        t.tally.stats[gi].values += t.identical_counts[gi];
      if (t.mode == Topic::Mode::Fields) {
        const auto& groups = t.layout->groups();
        for (std::size_t gi = 0; gi < groups.size(); ++gi) {
          if (t.tally.stats[gi].values > 0)
            row(groups[gi].path, to_string(groups[gi].kind), t.tally.stats[gi], has_step);
        }
      } else {
        row("(bytes)", "bytes", t.tally.stats[t.bytes_stat], false);
      }
      row("(log_time)", "time", t.tally.stats[t.time_stat], has_step);
    }
    if (first_only_ && report_.first) {
      const auto [ti, si] = *first_only_;
      add_detail(*report_.first, only_summary(topics_[ti], si));
    }
    report_.diverging_values += values_.diverging_values;
    report_.metadata.insert(report_.metadata.end(),
                            std::make_move_iterator(values_.metadata_differences.begin()),
                            std::make_move_iterator(values_.metadata_differences.end()));
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
  Values values_{o_};  // the value comparison: tolerance, per-field statistics, metadata differences
  Key first_key_;
  std::uint64_t problem_ordinal_ = 0;
  bool last_has_step_ = false;
  std::uint64_t last_step_ = 0;
  std::optional<std::pair<std::size_t, int>> first_only_;  // the first divergence is a step in one file only
};

}  // namespace

Result<CheckReport> check_logs(const std::string& run_path, const std::string& golden_path,
                               const CheckOptions& options) {
  Comparer c(options, run_path, golden_path);
  return c.compare();
}

}  // namespace rbsim::check
