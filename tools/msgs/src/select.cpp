// Selecting topics by name or pattern: the one rule of every command (rbsim/msgs.hpp).
#include <algorithm>
#include <optional>
#include <regex>
#include <set>

#include "rbsim/msgs.hpp"

namespace rbsim::msgs {

namespace {

Result<std::optional<std::regex>> pattern(const std::string& text, const char* option) {
  if (text.empty()) return std::optional<std::regex>();
  try {
    return std::optional<std::regex>(std::regex(text, std::regex::ECMAScript));
  } catch (const std::regex_error& e) {
    return Error{std::string(option) + " \"" + text + "\": not a regular expression (" + e.what() + ")",
                 ErrorCode::InvalidArgument};
  }
}

// Which candidates the names of `names` select; an error for a name that selects none.
Result<std::vector<bool>> named(const std::vector<std::string>& names,
                                std::span<const TopicCandidate> candidates) {
  std::vector<bool> out(candidates.size(), false);
  for (const std::string& name : names) {
    if (name.empty()) continue;
    bool found = false;
    for (std::size_t i = 0; i < candidates.size(); ++i) {
      if (!selects_topic(name, candidates[i])) continue;
      out[i] = true;
      found = true;
    }
    if (!found) return unknown_topic(name, candidates);
  }
  return out;
}

}  // namespace

std::vector<TopicCandidate> topic_candidates(std::string_view ns, bool events) {
  std::vector<TopicCandidate> out;
  for (const TopicSpec& spec : topics()) {
    if (events || !spec.event) out.push_back({topic_name(spec, ns), &spec});
  }
  return out;
}

bool selects_topic(std::string_view requested, const TopicCandidate& topic) {
  if (requested.empty()) return false;
  return names_topic(requested, topic.name) || (topic.spec != nullptr && requested == topic.spec->suffix);
}

Result<std::vector<std::size_t>> select_topics(const TopicFilter& filter,
                                               std::span<const TopicCandidate> candidates) {
  Result<std::vector<bool>> include = named(filter.topics, candidates);
  if (!include) return include.error();
  Result<std::vector<bool>> exclude = named(filter.exclude_topics, candidates);
  if (!exclude) return exclude.error();
  Result<std::optional<std::regex>> match = pattern(filter.regex, "--regex");
  if (!match) return match.error();
  Result<std::optional<std::regex>> unmatch = pattern(filter.exclude_regex, "--exclude-regex");
  if (!unmatch) return unmatch.error();
  const bool all = std::none_of(filter.topics.begin(), filter.topics.end(),
                                [](const std::string& n) { return !n.empty(); }) &&
                   filter.regex.empty();
  std::vector<std::size_t> out;
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    const std::string& name = candidates[i].name;
    const std::optional<std::regex>& keep = match.value();
    const std::optional<std::regex>& drop = unmatch.value();
    const bool chosen = all || include.value()[i] || (keep && std::regex_match(name, *keep));
    const bool dropped = exclude.value()[i] || (drop && std::regex_match(name, *drop));
    if (chosen && !dropped) out.push_back(i);
  }
  return out;
}

Error unknown_topic(std::string_view requested, std::span<const TopicCandidate> candidates) {
  std::set<std::string> names;
  for (const TopicCandidate& c : candidates) names.insert(c.name);
  std::string known;
  for (const std::string& n : names) known += (known.empty() ? "" : ", ") + n;
  return Error{"unknown topic \"" + std::string(requested) +
               "\" (topics: " + (known.empty() ? "none" : known) + ")"};
}

}  // namespace rbsim::msgs
