// rbsim log cat: messages as JSON lines, or one topic as CSV.
#include "rbsim/cat.hpp"

#include <charconv>
#include <cmath>
#include <map>
#include <set>

#include "rbsim/msgs.hpp"
#include "rbsim/recording.hpp"
#include "select.hpp"

namespace rbsim::recordings {

namespace {

struct ChannelDecoder {
  std::optional<msgs::MessageDecoder> decoder;  // empty: not decodable, data is null
};

void append_csv_value(std::string& out, const msgs::Scalar& s) {
  switch (s.kind) {
    case msgs::Scalar::Kind::Float: {
      char buf[32];
      const auto r = std::to_chars(buf, buf + sizeof buf, s.f);
      out.append(buf, r.ptr);
      return;
    }
    case msgs::Scalar::Kind::String:
      if (s.s.find_first_of(",\"\r\n") == std::string_view::npos) {
        out += s.s;
      } else {
        out += '"';
        for (char c : s.s) out += c == '"' ? std::string("\"\"") : std::string(1, c);
        out += '"';
      }
      return;
    default:
      out += s.to_string();
  }
}

// One topic as CSV: the columns are the first message's flattened fields ("bodies[3].x",
// "bodies.length"); every later message must have the same shape (the same sequence lengths).
class CsvTable {
 public:
  Status row(const msgs::MessageDecoder& decoder, const RecordedMessage& rm, std::string& line,
             const std::function<void(std::string_view)>& on_line) {
    const mcap::Message& m = *rm.message;
    if (Status st = decoder.decode(rm.cdr(), values_); !st) return st;
    if (!started_) {
      line = "log_time,publish_time,sequence";
      for (std::size_t i = 0; i < values_.size(); ++i) {
        line += ',' + decoder.path(rm.cdr(), i);
        if (values_[i].kind == msgs::Scalar::Kind::Length) lengths_.emplace_back(i, values_[i].u);
      }
      on_line(line);
      columns_ = values_.size();
      started_ = true;
    }
    bool same = values_.size() == columns_;
    for (const auto& [i, n] : lengths_)
      same = same && values_[i].kind == msgs::Scalar::Kind::Length && values_[i].u == n;
    if (!same) {
      return Error{"its flattened fields differ from the first message's (" + std::to_string(values_.size()) +
                   " values, not " + std::to_string(columns_) +
                   ", or other sequence lengths): CSV has one set of columns per topic (use --format json)"};
    }
    line =
        std::to_string(m.log_time) + ',' + std::to_string(m.publish_time) + ',' + std::to_string(m.sequence);
    for (const msgs::Scalar& s : values_) {
      line += ',';
      append_csv_value(line, s);
    }
    on_line(line);
    return Ok{};
  }

 private:
  bool started_ = false;
  std::size_t columns_ = 0;
  std::vector<std::pair<std::size_t, std::uint64_t>> lengths_;  // (index, value) of each length
  std::vector<msgs::Scalar> values_;
};

void append_json_head(std::string& line, const RecordedMessage& rm) {
  const mcap::Message& m = *rm.message;
  line.clear();
  line += "{\"topic\":";
  msgs::append_json_string(line, rm.topic());
  line += ",\"sequence\":" + std::to_string(m.sequence);
  line += ",\"log_time\":" + std::to_string(m.log_time);
  line += ",\"publish_time\":" + std::to_string(m.publish_time);
  line += ",\"data\":";
}

}  // namespace

Status cat(const std::string& path, const CatOptions& options,
           const std::function<void(std::string_view line)>& on_line) {
  auto opened = Recording::open(path, raw_options());  // every topic as recorded, whatever its type
  if (!opened) return opened.error();
  Recording& recording = *opened.value();

  MessageFilter filter;
  if (const auto start = detail::to_ns(options.start)) filter.start = *start;
  if (const auto end = detail::to_ns(options.end)) filter.end = *end;
  auto chosen = detail::choose_topics(recording, options.topics);
  if (!chosen) return chosen.error();
  filter.topics = std::move(chosen.value());
  const bool csv = options.format == CatFormat::Csv;
  if (csv && filter.topics.size() != 1) {
    std::set<std::string> topics;
    for (const RecordedChannel& c : recording.channels()) topics.insert(c.channel->topic);
    if (!filter.topics.empty() || topics.size() != 1) {
      std::string list;
      for (const std::string& t : topics) list += (list.empty() ? "" : ", ") + t;
      return Error{path + ": CSV prints one topic at a time: choose one (topics: " +
                   (list.empty() ? "none" : list) + ")"};
    }
    filter.topics = {*topics.begin()};
  }

  std::map<std::uint16_t, ChannelDecoder> decoders;
  CsvTable table;
  std::string line;
  Status failure = Ok{};
  const Status read = recording.read_messages(filter, [&](const RecordedMessage& rm) -> bool {
    const mcap::Message& m = *rm.message;
    const mcap::Schema* schema = rm.channel->schema;
    auto [it, fresh] = decoders.try_emplace(m.channel_id);
    if (fresh && schema != nullptr && schema->encoding == "ros2msg" &&
        rm.channel->channel->message_encoding == "cdr") {
      auto decoder = msgs::MessageDecoder::create(schema->name, rm.channel->schema_text());
      if (!decoder) {
        failure = with_context(path + ": schema " + schema->name + ": ", decoder.error());
        return false;
      }
      it->second.decoder = std::move(decoder.value());
    }
    const auto at = [&] {
      return path + ": " + rm.topic() + " message at log time " + std::to_string(m.log_time) + " ns: ";
    };
    if (csv) {
      if (!it->second.decoder) {
        failure =
            Error{at() + "no ros2msg schema with CDR encoding: no columns to print (use --format json)"};
      } else if (Status st = table.row(*it->second.decoder, rm, line, on_line); !st) {
        failure = with_context(at(), st.error());
      }
      return static_cast<bool>(failure);
    }
    append_json_head(line, rm);
    if (it->second.decoder) {
      if (Status st = it->second.decoder->to_json(rm.cdr(), line); !st) {
        failure = with_context(at(), st.error());
        return false;
      }
    } else {
      line += "null";
    }
    line += '}';
    on_line(line);
    return true;
  });
  if (!read) return read;
  return failure;
}

}  // namespace rbsim::recordings
