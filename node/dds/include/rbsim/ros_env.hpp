// The DDS domain and Cyclone DDS configuration from ROS 2's environment variables, mapped as
// rcl (rcl/src/rcl/{domain_id,localhost,discovery_options,init}.c) parses them and
// rmw_cyclonedds_cpp (check_create_domain in rmw_node.cpp) turns them into Cyclone configuration;
// rbsim's LOCALHOST is its compiled-in loopback configuration. Pure functions: no DDS, no getenv
// except in RosEnvironment::from_process().
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "rbsim/core.hpp"
#include "rbsim/middleware.hpp"  // NodeName

namespace rbsim::node {

// Domain ids that map onto valid UDP ports with the default port mapping.
inline constexpr std::uint32_t kMaxDomainId = 232;

// ROS_AUTOMATIC_DISCOVERY_RANGE.
enum class DiscoveryRange { Localhost, Subnet, Off, SystemDefault };
std::string_view to_string(DiscoveryRange range);  // "LOCALHOST", "SUBNET", "OFF", "SYSTEM_DEFAULT"

// The variables as found; nullopt: not set. An empty value means the same as not set.
struct RosEnvironment {
  std::optional<std::string> ros_domain_id;                    // ROS_DOMAIN_ID
  std::optional<std::string> ros_automatic_discovery_range;    // ROS_AUTOMATIC_DISCOVERY_RANGE
  std::optional<std::string> ros_static_peers;                 // ROS_STATIC_PEERS
  std::optional<std::string> ros_localhost_only;               // ROS_LOCALHOST_ONLY (deprecated in ROS 2)
  std::optional<std::string> cyclonedds_uri;                   // CYCLONEDDS_URI
  std::optional<std::string> ros_distro;                       // ROS_DISTRO
  std::optional<std::string> ros_security_enable{};            // ROS_SECURITY_ENABLE (rbsim/security.hpp)
  std::optional<std::string> ros_security_strategy{};          // ROS_SECURITY_STRATEGY
  std::optional<std::string> ros_security_keystore{};          // ROS_SECURITY_KEYSTORE
  std::optional<std::string> ros_security_enclave_override{};  // ROS_SECURITY_ENCLAVE_OVERRIDE
  static RosEnvironment from_process();                        // reads the process environment
};

// The ROS 2 wire format rbsim speaks on the graph (ROS_DISTRO). Humble (and Foxy, Galactic):
// 24-byte GIDs (rmw_dds_common/msg/Gid is char[24]), no type hashes in endpoint USER_DATA. Jazzy
// (and Iron, Kilted, Rolling): 16-byte GIDs and "typehash=RIHS01_...;" (REP 2011). Both
// rmw_cyclonedds_cpp versions make a GID of the entity's DDS GUID, zero-padded.
enum class RosDistro : std::uint8_t { Humble, Jazzy };
std::size_t gid_size(RosDistro distro);  // 24 or 16
bool has_type_hashes(RosDistro distro);  // whether endpoints carry typehash= in USER_DATA
struct DistroChoice {
  RosDistro distro = RosDistro::Jazzy;
  std::optional<std::string> warning;  // an unknown ROS_DISTRO: Jazzy's format is used
};
// Unset or empty: Jazzy, silently.
DistroChoice resolve_ros_distro(const RosEnvironment& env);

// "a/b/sim" or "/a/b/sim": ROS 2 name tokens (letters, digits, '_', not starting with a digit)
// separated by single '/'; the last one is the node name. Fails naming what is wrong.
Result<NodeName> parse_node_name(std::string_view path);

struct DdsSettings {
  std::uint32_t domain = 0;
  RosDistro distro = RosDistro::Jazzy;  // ROS_DISTRO (resolve_ros_distro; an unknown one is a warning)
  DiscoveryRange range = DiscoveryRange::Localhost;
  std::vector<std::string> static_peers;  // the peers the configuration contains
  // The configuration to create the domain with (dds_create_domain); nullopt: none, Cyclone
  // reads CYCLONEDDS_URI itself, or uses its own defaults when that is not set either.
  std::optional<std::string> config;
  bool from_cyclonedds_uri = false;   // CYCLONEDDS_URI is set: it configures everything but the domain id
  std::vector<std::string> warnings;  // values that are valid but ignored, one line each
  // "domain 7 (LOCALHOST)", "domain 0 (CYCLONEDDS_URI)", "domain 3 (SUBNET, static peers a;b)".
  std::string describe() const;
};

// `explicit_domain` (rbsim's --domain) wins over ROS_DOMAIN_ID, which is then not looked at.
// Errors are one line and name the variable: a ROS_DOMAIN_ID that is not an integer 0..232, an
// unknown ROS_AUTOMATIC_DISCOVERY_RANGE, a ROS_LOCALHOST_ONLY other than 0 or 1, a
// ROS_STATIC_PEERS entry that is not a host name or address. `pid` names the discovery tag of
// the OFF range (as rmw_cyclonedds_cpp: only this process can match it).
Result<DdsSettings> resolve_dds_settings(const RosEnvironment& env,
                                         std::optional<std::uint32_t> explicit_domain, std::int64_t pid);

// ROS_DOMAIN_ID alone: nullopt when unset or empty.
Result<std::optional<std::uint32_t>> domain_from_environment(const RosEnvironment& env);

}  // namespace rbsim::node
