// ROS 2's environment variables onto a Cyclone DDS domain and configuration (rbsim/ros_env.hpp).
#include "rbsim/ros_env.hpp"

#include <cstdlib>

#include "topics.hpp"

namespace rbsim::node {

namespace {
bool empty(const std::optional<std::string>& v) {
  return !v || v->empty();
}

std::string quoted(std::string_view name, std::string_view value) {
  return std::string(name) + "='" + std::string(value) + "'";
}

// rcl reads ROS_DOMAIN_ID with strtoul; rbsim takes plain decimal digits only and Cyclone's
// range, and says so instead of running on another domain than the one meant.
Result<std::uint32_t> parse_domain(std::string_view text) {
  const std::string bad = quoted("ROS_DOMAIN_ID", text);
  if (text.empty() || text.size() > 9 || text.find_first_not_of("0123456789") != std::string_view::npos) {
    return Error{bad + " is not a DDS domain id: an integer in [0, " + std::to_string(kMaxDomainId) + "]"};
  }
  const auto id = static_cast<std::uint32_t>(std::stoul(std::string(text)));
  if (id > kMaxDomainId) {
    return Error{bad + ": domain id " + std::to_string(id) + " out of range [0, " +
                 std::to_string(kMaxDomainId) + "]"};
  }
  return id;
}

std::string_view trim(std::string_view s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string_view::npos) return {};
  const auto e = s.find_last_not_of(" \t");
  return s.substr(b, e - b + 1);
}

// rcl splits ROS_STATIC_PEERS at ';' (empty entries dropped) and skips entries longer than
// 255 characters with a warning; rbsim refuses those and anything that is not a host name or
// address (the entry goes into XML: no quotes, angle brackets or ampersands get through).
Result<std::vector<std::string>> parse_peers(std::string_view text) {
  std::vector<std::string> peers;
  while (!text.empty()) {
    const auto semi = text.find(';');
    const std::string_view item = trim(text.substr(0, semi));
    text = semi == std::string_view::npos ? std::string_view{} : text.substr(semi + 1);
    if (item.empty()) continue;
    if (item.size() > 255) {
      return Error{"ROS_STATIC_PEERS: peer '" + std::string(item.substr(0, 40)) +
                   "...' is longer than 255 characters"};
    }
    constexpr std::string_view kAllowed =
        "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789.-_:[]%";
    if (item.find_first_not_of(kAllowed) != std::string_view::npos) {
      return Error{"ROS_STATIC_PEERS: '" + std::string(item) +
                   "' is not a host name or IP address (peers are separated by ';')"};
    }
    peers.emplace_back(item);
  }
  return peers;
}

// A peer on this host: reachable with the loopback interface alone.
bool is_loopback_peer(std::string_view peer) {
  const std::string_view host = peer.starts_with("[") ? peer.substr(1) : peer;
  return host.starts_with("127.") || host == "localhost" || host.starts_with("localhost:") ||
         host.starts_with("::1");
}

constexpr std::string_view kHead = R"(<CycloneDDS xmlns="https://cdds.io/config"><Domain Id="any">)";
constexpr std::string_view kTail = "</Domain></CycloneDDS>";
constexpr std::string_view kLoopbackInterface =
    R"(<Interfaces><NetworkInterface address="127.0.0.1"/></Interfaces>)";
// rbsim's discovery settings (as in cyclonedds-loopback.xml): a crashed subscriber is noticed
// after 2 s, and unicast discovery reaches participant indices 0..100 on each peer.
constexpr std::string_view kIndexAndLease =
    "<LeaseDuration>2 s</LeaseDuration><ParticipantIndex>auto</ParticipantIndex>"
    "<MaxAutoParticipantIndex>100</MaxAutoParticipantIndex>";

std::string peers_xml(const std::vector<std::string>& peers) {
  std::string xml = "<Peers>";
  for (const std::string& p : peers) xml += "<Peer Address=\"" + p + "\"/>";
  return xml + "</Peers>";
}
}  // namespace

std::string_view to_string(DiscoveryRange range) {
  switch (range) {
    case DiscoveryRange::Localhost:
      return "LOCALHOST";
    case DiscoveryRange::Subnet:
      return "SUBNET";
    case DiscoveryRange::Off:
      return "OFF";
    case DiscoveryRange::SystemDefault:
      return "SYSTEM_DEFAULT";
  }
  return "?";
}

RosEnvironment RosEnvironment::from_process() {
  auto get = [](const char* name) -> std::optional<std::string> {
    const char* v = std::getenv(name);
    return v != nullptr ? std::optional<std::string>(v) : std::nullopt;
  };
  return {get("ROS_DOMAIN_ID"),         get("ROS_AUTOMATIC_DISCOVERY_RANGE"),
          get("ROS_STATIC_PEERS"),      get("ROS_LOCALHOST_ONLY"),
          get("CYCLONEDDS_URI"),        get("ROS_DISTRO"),
          get("ROS_SECURITY_ENABLE"),   get("ROS_SECURITY_STRATEGY"),
          get("ROS_SECURITY_KEYSTORE"), get("ROS_SECURITY_ENCLAVE_OVERRIDE")};
}

std::size_t gid_size(RosDistro distro) {
  return distro == RosDistro::Humble ? 24 : 16;
}
bool has_type_hashes(RosDistro distro) {
  return distro != RosDistro::Humble;
}

DistroChoice resolve_ros_distro(const RosEnvironment& env) {
  if (empty(env.ros_distro)) return {};
  const std::string& v = *env.ros_distro;
  // rmw_dds_common's Gid went from char[24] to char[16], and type hashes came, in Iron.
  for (std::string_view old : {"foxy", "galactic", "humble"}) {
    if (v == old) return {RosDistro::Humble, std::nullopt};
  }
  for (std::string_view recent : {"iron", "jazzy", "kilted", "lyrical", "rolling"}) {
    if (v == recent) return {};
  }
  return {RosDistro::Jazzy,
          quoted("ROS_DISTRO", v) +
              " is not a ROS 2 distribution rbsim knows (humble, jazzy, ...): it speaks Jazzy's "
              "graph format (16-byte GIDs, type hashes)"};
}

namespace {
// rmw_validate_node_name / rmw_validate_namespace's token rule.
std::string name_token_problem(std::string_view token) {
  if (token.empty()) return "has an empty token (\"//\", or a '/' at the end)";
  if (token.front() >= '0' && token.front() <= '9') return "has a token starting with a digit";
  for (const char c : token) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
    if (!ok) return std::string("may hold only letters, digits, '_' and '/' (got '") + c + "')";
  }
  return {};
}
}  // namespace

Result<NodeName> parse_node_name(std::string_view path) {
  const std::string shown(path);
  if (!path.empty() && path.front() == '/') path.remove_prefix(1);
  // rmw's limits: 255 characters for the node name, 4096 for the fully qualified one (less
  // rmw's topic prefix).
  if (path.empty()) return Error{"\"" + shown + "\" is not a ROS 2 node name: it is empty"};
  if (path.size() > 4000)
    return Error{"\"" + shown.substr(0, 40) + "...\" is not a ROS 2 node name: too long"};
  NodeName out;
  out.ns.clear();
  while (true) {
    const auto slash = path.find('/');
    const std::string_view token = path.substr(0, slash);
    if (std::string problem = name_token_problem(token); !problem.empty()) {
      return Error{"\"" + shown + "\" is not a ROS 2 node name: it " + problem};
    }
    if (slash == std::string_view::npos) {
      if (token.size() > 255)
        return Error{"\"" + shown + "\" is not a ROS 2 node name: its name is over 255 characters"};
      out.name = std::string(token);
      break;
    }
    out.ns += "/" + std::string(token);
    path.remove_prefix(slash + 1);
  }
  if (out.ns.empty()) out.ns = "/";
  return out;
}

std::string DdsSettings::describe() const {
  std::string s = "domain " + std::to_string(domain) + " (";
  if (from_cyclonedds_uri) return s + "CYCLONEDDS_URI)";
  s += to_string(range);
  if (!static_peers.empty()) {
    s += ", static peers ";
    for (std::size_t i = 0; i < static_peers.size(); ++i) s += (i > 0 ? ";" : "") + static_peers[i];
  }
  return s + ")";
}

Result<std::optional<std::uint32_t>> domain_from_environment(const RosEnvironment& env) {
  if (empty(env.ros_domain_id)) return std::optional<std::uint32_t>{};
  auto id = parse_domain(*env.ros_domain_id);
  if (!id) return id.error();
  return std::optional<std::uint32_t>(id.value());
}

namespace {
// The domain: --domain, else ROS_DOMAIN_ID, else 0 (rcl_get_default_domain_id).
Result<std::uint32_t> resolve_domain(const RosEnvironment& env,
                                     std::optional<std::uint32_t> explicit_domain) {
  if (explicit_domain) {
    if (*explicit_domain > kMaxDomainId) {
      return Error{"domain id " + std::to_string(*explicit_domain) + " out of range [0, " +
                   std::to_string(kMaxDomainId) + "]"};
    }
    return *explicit_domain;
  }
  auto from_env = domain_from_environment(env);
  if (!from_env) return from_env.error();
  return from_env.value().value_or(0);
}

// ROS_LOCALHOST_ONLY (rcl_get_localhost_only): "1" enables it; rcl takes any other non-empty
// value for "disabled", rbsim only "0" and refuses the rest (a "true" meant to enable it).
Result<bool> localhost_only_from(const RosEnvironment& env) {
  bool localhost_only = false;
  if (!empty(env.ros_localhost_only)) {
    if (*env.ros_localhost_only == "1") {
      localhost_only = true;
    } else if (*env.ros_localhost_only != "0") {
      return Error{quoted("ROS_LOCALHOST_ONLY", *env.ros_localhost_only) +
                   " is neither 1 nor 0 (deprecated: use ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST)"};
    }
  }
  return localhost_only;
}

// ROS_AUTOMATIC_DISCOVERY_RANGE (rcl_get_automatic_discovery_range): exact names, empty or
// unset means LOCALHOST; rcl warns about an unknown value and assumes LOCALHOST, rbsim refuses it.
Result<DiscoveryRange> discovery_range_from(const RosEnvironment& env) {
  DiscoveryRange range = DiscoveryRange::Localhost;
  if (!empty(env.ros_automatic_discovery_range)) {
    const std::string& v = *env.ros_automatic_discovery_range;
    if (v == "LOCALHOST") {
      range = DiscoveryRange::Localhost;
    } else if (v == "SUBNET") {
      range = DiscoveryRange::Subnet;
    } else if (v == "OFF") {
      range = DiscoveryRange::Off;
    } else if (v == "SYSTEM_DEFAULT") {
      range = DiscoveryRange::SystemDefault;
    } else {
      return Error{quoted("ROS_AUTOMATIC_DISCOVERY_RANGE", v) +
                   " is not a discovery range: LOCALHOST, SUBNET, OFF or SYSTEM_DEFAULT"};
    }
  }
  return range;
}

// check_create_domain in rmw_cyclonedds_cpp: which range adds which Cyclone settings.
void configure_discovery(DdsSettings& s, DiscoveryRange range, const std::vector<std::string>& peers,
                         std::int64_t pid) {
  switch (range) {
    case DiscoveryRange::Localhost: {
      // rbsim's loopback configuration, byte for byte, unless there are static peers: they are
      // added after 127.0.0.1 (as rmw adds them after localhost); a peer on another host needs
      // Cyclone's own choice of network interface instead of the loopback one. No multicast.
      if (peers.empty()) {
        s.config = std::string(kLoopbackConfig);
        break;
      }
      bool all_local = true;
      for (const std::string& p : peers) all_local = all_local && is_loopback_peer(p);
      std::vector<std::string> with_local{"127.0.0.1"};
      with_local.insert(with_local.end(), peers.begin(), peers.end());
      s.static_peers = peers;
      s.config = std::string(kHead) + "<General>" + (all_local ? std::string(kLoopbackInterface) : "") +
                 "<AllowMulticast>false</AllowMulticast></General><Discovery>" + std::string(kIndexAndLease) +
                 peers_xml(with_local) + "</Discovery>" + std::string(kTail);
      break;
    }
    case DiscoveryRange::Subnet:
      // Cyclone's interface selection and multicast; unicast discovery to the static peers too.
      s.static_peers = peers;
      s.config = std::string(kHead) + "<Discovery>" + std::string(kIndexAndLease) +
                 (peers.empty() ? "" : peers_xml(peers)) + "</Discovery>" + std::string(kTail);
      break;
    case DiscoveryRange::Off:
      // No discovery beyond this process: no multicast, no peers, no participant index, and a
      // discovery tag no other process has (rmw's "ros_discovery_off_<pid>"). rbsim also keeps
      // to the loopback interface: nothing needs to leave the host.
      if (!peers.empty()) {
        s.warnings.emplace_back("ROS_AUTOMATIC_DISCOVERY_RANGE=OFF: ROS_STATIC_PEERS is ignored");
      }
      s.config = std::string(kHead) + "<General>" + std::string(kLoopbackInterface) +
                 "<AllowMulticast>false</AllowMulticast></General><Discovery><ParticipantIndex>none</"
                 "ParticipantIndex><Tag>ros_discovery_off_" +
                 std::to_string(pid) + "</Tag></Discovery>" + std::string(kTail);
      break;
    case DiscoveryRange::SystemDefault:
      // Cyclone's defaults untouched.
      if (!peers.empty()) {
        s.warnings.emplace_back("ROS_AUTOMATIC_DISCOVERY_RANGE=SYSTEM_DEFAULT: ROS_STATIC_PEERS is ignored");
      }
      break;
  }
}
}  // namespace

Result<DdsSettings> resolve_dds_settings(const RosEnvironment& env,
                                         std::optional<std::uint32_t> explicit_domain, std::int64_t pid) {
  DdsSettings s;
  DistroChoice distro = resolve_ros_distro(env);
  s.distro = distro.distro;
  if (distro.warning) s.warnings.push_back(*distro.warning);
  auto domain = resolve_domain(env, explicit_domain);
  if (!domain) return domain.error();
  s.domain = domain.value();
  auto localhost_only_set = localhost_only_from(env);
  if (!localhost_only_set) return localhost_only_set.error();
  const bool localhost_only = localhost_only_set.value();
  auto range_set = discovery_range_from(env);
  if (!range_set) return range_set.error();
  DiscoveryRange range = range_set.value();
  auto peers = parse_peers(env.ros_static_peers.value_or(""));
  if (!peers) return peers.error();

  // rcl_init: an enabled ROS_LOCALHOST_ONLY wins over both newer variables.
  if (localhost_only) {
    if (!empty(env.ros_automatic_discovery_range) || !peers.value().empty()) {
      s.warnings.emplace_back(
          "ROS_LOCALHOST_ONLY=1 (deprecated) wins: ROS_AUTOMATIC_DISCOVERY_RANGE and ROS_STATIC_PEERS are "
          "ignored");
    }
    range = DiscoveryRange::Localhost;
    peers.value().clear();
  }
  s.range = range;

  // CYCLONEDDS_URI wins: Cyclone reads it, and the ROS variables only choose the domain id.
  if (!empty(env.cyclonedds_uri)) {
    s.from_cyclonedds_uri = true;
    if (!empty(env.ros_automatic_discovery_range) || !peers.value().empty() || localhost_only) {
      s.warnings.emplace_back(
          "CYCLONEDDS_URI is set: it configures discovery, so ROS_AUTOMATIC_DISCOVERY_RANGE, "
          "ROS_STATIC_PEERS "
          "and ROS_LOCALHOST_ONLY are ignored");
    }
    return s;
  }
  configure_discovery(s, range, peers.value(), pid);
  return s;
}

}  // namespace rbsim::node
