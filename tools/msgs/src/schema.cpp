// Topics, names and rosbag2-style ros2msg schemas.
#include <algorithm>
#include <functional>
#include <set>
#include <sstream>

#include "definitions.hpp"
#include "list_items.hpp"
#include "rbsim/msgs.hpp"

namespace rbsim::msgs {

namespace {
constexpr TopicSpec kTopics[kTopicCount] = {
    {TopicId::SceneDescription, "scene", "rbsim_msgs/msg/SceneDescription", true, false},
    {TopicId::Markers, "markers", "visualization_msgs/msg/MarkerArray", true, false},
    {TopicId::BodyStates, "body_states", "rbsim_msgs/msg/BodyStates", false, true},
    {TopicId::SpringStates, "spring_states", "rbsim_msgs/msg/SpringStates", false, true},
    {TopicId::Energy, "energy", "rbsim_msgs/msg/EnergyTerms", false, true},
    {TopicId::Tf, "tf", "tf2_msgs/msg/TFMessage", false, true},
    {TopicId::Springs, "springs", "visualization_msgs/msg/Marker", false, true},
    {TopicId::Clock, "clock", "rosgraph_msgs/msg/Clock", false, true},
    {TopicId::Poses, "poses", "geometry_msgs/msg/PoseArray", false, true},
    {TopicId::Commands, "commands", "rbsim_msgs/msg/Command", true, false, true},
};
static_assert([] {
  for (std::size_t i = 0; i < kTopicCount; ++i) {
    if (static_cast<std::size_t>(kTopics[i].id) != i) return false;
  }
  return true;
}());

// EnergyTerms.msg as builds before the potential split recorded it (their recordings are still
// read; the dependencies it names are unchanged).
constexpr std::string_view kEnergyTermsWithoutSplit =
    "std_msgs/Header header\n"
    "uint64 step\n"
    "BodyEnergy[] bodies\n"
    "ForcePotential[] forces\n"
    "Vector2 momentum            # totals over bodies\n"
    "float64 angular_momentum    # sum of L_point + L_spin\n"
    "float64 potential           # U = gravity + springs\n"
    "float64 kinetic_point\n"
    "float64 kinetic_spin\n"
    "float64 total               # U + T\n";

// "pkg/Name" or "pkg/msg/Name" -> "pkg/msg/Name"
std::string canonical(std::string_view type) {
  const auto slash = type.find('/');
  if (slash == std::string_view::npos) return std::string(type);
  if (type.find('/', slash + 1) != std::string_view::npos) return std::string(type);
  return std::string(type.substr(0, slash)) + "/msg/" + std::string(type.substr(slash + 1));
}

bool is_primitive(std::string_view t) {
  static constexpr std::string_view kPrimitives[] = {"bool",   "byte",  "char",   "float32", "float64",
                                                     "int8",   "uint8", "int16",  "uint16",  "int32",
                                                     "uint32", "int64", "uint64", "string",  "wstring"};
  if (t.starts_with("string<=") || t.starts_with("wstring<=")) return true;
  return std::find(std::begin(kPrimitives), std::end(kPrimitives), t) != std::end(kPrimitives);
}

// Non-primitive field types of a .msg text, as rosbag2 names them: as written when they carry a
// package, else prefixed with the package of the text. Sorted, unique (rosbag2 uses std::set).
std::set<std::string> dependencies(std::string_view text, std::string_view package) {
  std::set<std::string> deps;
  std::istringstream lines{std::string(text)};
  std::string line;
  while (std::getline(lines, line)) {
    const auto first = line.find_first_not_of(" \t");
    if (first == std::string::npos || line[first] == '#') continue;
    const auto end = line.find_first_of(" \t", first);
    std::string type = line.substr(first, end == std::string::npos ? std::string::npos : end - first);
    if (const auto bracket = type.find('['); bracket != std::string::npos) type.resize(bracket);
    if (type.empty() || is_primitive(type)) continue;
    deps.insert(type.find('/') == std::string::npos ? std::string(package) + "/" + type : type);
  }
  return deps;
}
}  // namespace

std::span<const TopicSpec> topics() {
  return kTopics;
}
const TopicSpec& topic(TopicId id) {
  return kTopics[static_cast<std::size_t>(id)];
}
const TopicSpec* topic_for_type(std::string_view type) {
  const std::string t = canonical_type(type, "");
  for (const TopicSpec& spec : kTopics) {
    if (spec.type == t) return &spec;
  }
  return nullptr;
}

bool names_topic(std::string_view requested, std::string_view topic) {
  if (requested == topic) return true;
  if (requested.empty() || requested.front() == '/' || requested.size() >= topic.size()) return false;
  return topic.ends_with(requested) && topic[topic.size() - requested.size() - 1] == '/';
}

TopicSet default_topics() {
  TopicSet set;
  set.set();
  set.reset(static_cast<std::size_t>(TopicId::Poses));
  set.reset(static_cast<std::size_t>(TopicId::Commands));  // an event topic: no World encodes it
  return set;
}

Result<TopicSet> parse_topic_set(std::string_view list, std::string_view ns) {
  TopicFilter filter;
  for (const std::string_view name : detail::list_items(list)) {
    if (!name.empty()) filter.topics.emplace_back(name);
  }
  if (filter.topics.empty()) return Error{"no topic given"};
  const std::vector<TopicCandidate> candidates = topic_candidates(ns, /*events=*/false);
  Result<std::vector<std::size_t>> chosen = select_topics(filter, candidates);
  if (!chosen) return chosen.error();
  TopicSet set;
  set.set(static_cast<std::size_t>(TopicId::SceneDescription));
  for (const std::size_t i : chosen.value()) set.set(static_cast<std::size_t>(candidates[i].spec->id));
  return set;
}

std::vector<TopicId> topic_ids(const TopicSet& set) {
  std::vector<TopicId> out;
  for (const TopicSpec& spec : kTopics) {
    if (set.test(static_cast<std::size_t>(spec.id))) out.push_back(spec.id);
  }
  return out;
}

std::string ros_namespace_problem(std::string_view ns) {
  if (ns.empty()) return "must not be empty";
  const std::size_t begin = ns[0] == '/' ? 1 : 0;
  if (begin == ns.size()) return "must name at least one token (\"/\" alone is the root)";
  if (ns.back() == '/') return "must not end with '/'";
  bool token_start = true;
  for (std::size_t i = begin; i < ns.size(); ++i) {
    const char c = ns[i];
    if (c == '/') {
      if (token_start) return "must not contain \"//\"";
      token_start = true;
      continue;
    }
    const bool letter = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z');
    const bool digit = c >= '0' && c <= '9';
    if (!letter && !digit && c != '_')
      return std::string("may hold only letters, digits, '_' and '/' (got '") + c + "')";
    if (token_start && digit) return "a token must not start with a digit";
    if (c == '_' && i > begin && ns[i - 1] == '_') return "must not contain repeated underscores";
    token_start = false;
  }
  return {};
}

std::string topic_name(const TopicSpec& spec, std::string_view ns) {
  if (spec.id == TopicId::Clock || spec.id == TopicId::Tf || ns.empty())
    return "/" + std::string(spec.suffix);
  std::string name = "/" + std::string(ns);
  while (name.size() > 1 && name.back() == '/') name.pop_back();
  if (name.size() > 1 && name[1] == '/') name.erase(0, 1);
  return name + "/" + std::string(spec.suffix);
}

std::string dds_topic_name(std::string_view ros_topic) {
  return "rt" + std::string(ros_topic.starts_with('/') ? "" : "/") + std::string(ros_topic);
}

std::string dds_type_name(std::string_view ros_type) {
  const std::string full = canonical(ros_type);
  const auto a = full.find('/'), b = full.rfind('/');
  return full.substr(0, a) + "::" + full.substr(a + 1, b - a - 1) + "::dds_::" + full.substr(b + 1) + "_";
}

OfferedQos offered_qos(const TopicSpec& spec, std::int32_t keep_last) {
  OfferedQos q;
  q.transient_local = spec.transient_local;
  q.keep_all = spec.event || (!spec.transient_local && keep_last <= 0);
  q.depth = q.keep_all ? 0 : spec.transient_local ? 1 : keep_last;
  return q;
}

std::string offered_qos_yaml(const OfferedQos& qos) {
  // rosbag2's encoding (yaml-cpp dump of a one-element sequence, format version >= 9: policies by
  // name); "infinite" durations are RMW_DURATION_INFINITE = {9223372036 s, 854775807 ns}. A keep-all
  // writer has no depth: 0, as rclcpp's KeepAll leaves it.
  const char* infinite = "\n    sec: 9223372036\n    nsec: 854775807";
  std::string y = qos.keep_all ? "- history: keep_all\n  depth: 0"
                               : "- history: keep_last\n  depth: " + std::to_string(qos.depth);
  y += "\n  reliability: reliable\n  durability: ";
  y += qos.transient_local ? "transient_local" : "volatile";
  y += std::string("\n  deadline:") + infinite + "\n  lifespan:" + infinite + "\n  liveliness: automatic" +
       "\n  liveliness_lease_duration:" + infinite + "\n  avoid_ros_namespace_conventions: false";
  return y;
}

namespace detail {
Result<std::string> definition_part(std::string_view type, std::string_view text, int part, int parts) {
  std::string texts[3];
  int separators = 0;
  while (!text.empty()) {
    const auto nl = text.find('\n');
    std::string_view line = text.substr(0, nl);
    text = nl == std::string_view::npos ? std::string_view() : text.substr(nl + 1);
    std::string_view bare = line;
    while (!bare.empty() && (bare.back() == '\r' || bare.back() == ' ' || bare.back() == '\t'))
      bare.remove_suffix(1);
    if (bare == "---") {
      ++separators;
      continue;
    }
    if (separators < 3) texts[separators] += std::string(line) + "\n";
  }
  if (separators != parts - 1) {
    const char* what = parts == 2 ? "a service definition needs exactly one \"---\" line"
                                  : "an action definition needs exactly two \"---\" lines";
    return Error{std::string(type) + ": " + what + " (found " + std::to_string(separators) + ")"};
  }
  return std::move(texts[part]);
}

}  // namespace detail

std::string_view definition(std::string_view type) {
  const std::string key = canonical(type);
  for (const detail::Definition& d : detail::definitions()) {
    if (d.type == key) return d.text;
  }
  return {};
}

std::vector<std::string_view> definition_types() {
  std::vector<std::string_view> out;
  for (const detail::Definition& d : detail::definitions()) {
    if (d.type.find("/msg/") != std::string_view::npos) out.push_back(d.type);
  }
  return out;
}

std::vector<std::string_view> service_types() {
  std::vector<std::string_view> out;
  for (const detail::Definition& d : detail::definitions()) {
    if (d.type.find("/srv/") != std::string_view::npos) out.push_back(d.type);
  }
  return out;
}

std::vector<std::string_view> action_types() {
  std::vector<std::string_view> out;
  for (const detail::Definition& d : detail::definitions()) {
    if (d.type.find("/action/") != std::string_view::npos) out.push_back(d.type);
  }
  return out;
}

namespace {
// The .msg text rosidl makes of a service's messages (rosidl_parser's Service): "pkg/srv/Name_Request"
// and "_Response" are the two parts of the .srv text (either may be empty: std_srvs/srv/Trigger's
// request has no field), "_Event" is rosidl's event_message: the ServiceEventInfo, then the request
// and the response each as a sequence of at most one (named in full: the parts have no .msg of their
// own to be found by a bare name). nullopt for another name or a service we do not carry.
std::optional<std::string> service_message_text(std::string_view type) {
  for (const std::string_view suffix : {kServiceRequestSuffix, kServiceResponseSuffix, kServiceEventSuffix}) {
    if (!type.ends_with(suffix) || type.find("/srv/") == std::string_view::npos) continue;
    const std::string service(type.substr(0, type.size() - suffix.size()));
    const std::string_view srv = definition(service);
    if (srv.empty()) return std::nullopt;
    if (suffix == kServiceEventSuffix) {
      return "service_msgs/ServiceEventInfo info\n" + service + std::string(kServiceRequestSuffix) +
             "[<=1] request\n" + service + std::string(kServiceResponseSuffix) + "[<=1] response\n";
    }
    Result<std::string> part =
        detail::definition_part(service, srv, suffix == kServiceRequestSuffix ? 0 : 1, 2);
    if (!part) return std::nullopt;
    return std::move(part.value());
  }
  return std::nullopt;
}

// The text of a type: its shipped .msg, or a service message's (service_message_text).
std::optional<std::string> text_of(std::string_view type) {
  const std::string_view shipped = definition(type);
  if (!shipped.empty()) return std::string(shipped);
  return service_message_text(type);
}

// The rosbag2 schema of `root` whose own text is `root_text` (its dependencies from definitions).
Result<std::string> schema_of(std::string_view root, const std::optional<std::string>& root_text) {
  std::set<std::string> seen;
  std::string missing;
  std::function<std::string(std::string_view, int)> expand = [&](std::string_view type, int depth) {
    const std::optional<std::string> text = depth == 0 ? root_text : text_of(type);
    if (!text || depth > 50) {
      missing = std::string(type);
      return std::string();
    }
    std::string out(*text);
    const std::string package = canonical(type).substr(0, canonical(type).find('/'));
    for (const std::string& dep : dependencies(*text, package)) {
      if (!seen.insert(dep).second) continue;
      out += "\n" + std::string(80, '=') + "\nMSG: " + dep + "\n";
      out += expand(dep, depth + 1);
    }
    return out;
  };
  std::string schema = expand(root, 0);
  if (!missing.empty()) return Error{"no message definition for " + missing};
  return schema;
}
}  // namespace

Result<std::string> ros2msg_schema(std::string_view root) {
  return schema_of(root, text_of(root));
}

std::optional<EnergyTermsVersion> energy_terms_version(std::string_view schema) {
  const std::string_view type = topic(TopicId::Energy).type;
  if (Result<std::string> now = ros2msg_schema(type); now && now.value() == schema) {
    return EnergyTermsVersion::Current;
  }
  if (Result<std::string> old = schema_of(type, std::string(kEnergyTermsWithoutSplit));
      old && old.value() == schema) {
    return EnergyTermsVersion::WithoutSplit;
  }
  return std::nullopt;
}

}  // namespace rbsim::msgs
