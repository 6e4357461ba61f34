// The messages a ROS 2 process sends about itself rather than about the simulation: the graph
// entry every rmw_dds_common-based rmw publishes on ros_discovery_info
// (rmw_dds_common/msg/ParticipantEntitiesInfo) and rcl's log messages on /rosout
// (rcl_interfaces/msg/Log), encoded as CDR with the one CDR writer.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "rbsim/msgs.hpp"
#include "rbsim/print.hpp"

namespace rbsim::msgs {

inline constexpr std::string_view kParticipantEntitiesInfoType = "rmw_dds_common/msg/ParticipantEntitiesInfo";
inline constexpr std::string_view kLogType = "rcl_interfaces/msg/Log";

// A DDS GUID (participant or endpoint): the 16 bytes rmw_cyclonedds_cpp puts into a GID.
using Guid = std::array<std::uint8_t, 16>;

// rmw_dds_common/msg/NodeEntitiesInfo.
struct NodeEntities {
  std::string ns;    // "/" or "/a/b"
  std::string name;  // "sim"
  std::vector<Guid> readers, writers;
};
// rmw_dds_common/msg/ParticipantEntitiesInfo: `gid_size` is the distro's rmw_dds_common/msg/Gid
// (char[16] since Iron, char[24] before): a GID is the GUID followed by zeros up to it.
struct ParticipantEntities {
  Guid participant{};
  std::vector<NodeEntities> nodes;
};
void encode_participant_entities(const ParticipantEntities& info, std::size_t gid_size, Bytes& out);

// rcl_interfaces/msg/Log's levels (its constants DEBUG .. FATAL).
using LogLevel = print::Level;  // rcl_interfaces/msg/Log's levels (rbsim/print.hpp)
struct LogMessage {
  Time stamp;
  LogLevel level = LogLevel::Info;
  std::string_view name, msg, file, function;
  std::uint32_t line = 0;
};
void encode_log(const LogMessage& log, Bytes& out);

}  // namespace rbsim::msgs
