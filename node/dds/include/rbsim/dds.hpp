// The middleware seam's backend on Eclipse Cyclone DDS, with ROS 2 conventions as
// rmw_cyclonedds_cpp has them, so a ROS 2 system using it sees rbsim's nodes: topics
// "rt/<namespace>/<name>" of types "pkg::msg::dds_::Name_" carrying raw CDR (the exact bytes
// rbsim_msgs encodes, 4-byte encapsulation header included), services on rmw_cyclonedds_cpp's
// wire format (below), and each participant one ROS 2 node on the graph: its USER_DATA says
// "enclave=/;", and it publishes ros_discovery_info listing the node with every endpoint created
// in the graph (rbsim/graph.hpp), in the GID format ROS_DISTRO selects (rbsim/ros_env.hpp).
//
// Services, as rmw_cyclonedds_cpp puts them on the wire:
//   - service "/rbsim/pause" is two topics, requests on "rq/rbsim/pauseRequest" and replies on
//     "rr/rbsim/pauseReply", of types "pkg::srv::dds_::Name_Request_" / "Name_Response_";
//   - every request and reply is CDR with rmw_cyclonedds's request header (cdds_request_header_t:
//     u64 client id, i64 sequence number) first, then the message's fields, aligned as if the header
//     were not there (it is 16 bytes, a multiple of every alignment); a reply carries its request's
//     header back unchanged, and a client keeps the replies whose id is its own (its request
//     writer's instance handle);
//   - the QoS is rmw_qos_profile_services_default (reliable, volatile, keep last 10), and each
//     endpoint's USER_DATA says "clientid=<id>;" or "serviceid=<id>;" (one id for an endpoint pair),
//     then a node's endpoint's type hashes, so a server can tell whether a client's reply reader is
//     matched before it answers.
// A server takes requests on Cyclone's receive thread (a DDS listener) into its bounded queue. A
// reply to a client whose reply reader is not matched yet is kept (bounded) and retried at later
// serve() calls for a short while, instead of waiting as rmw_cyclonedds does (up to 100 ms inside
// rmw_send_response); a client that is gone gets none.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include "rbsim/bytes.hpp"
#include "rbsim/middleware.hpp"
#include "rbsim/ros_env.hpp"
#include "rbsim/service.hpp"
#include "rbsim/status.hpp"

namespace rbsim::node {

// A DDS participant, configured by ROS 2's environment variables (rbsim/ros_env.hpp): by default
// (ROS_AUTOMATIC_DISCOVERY_RANGE unset or LOCALHOST, no ROS_STATIC_PEERS) the domain runs on
// rbsim's loopback configuration (127.0.0.1 only, no multicast, ParticipantIndex auto); with
// CYCLONEDDS_URI set, on whatever that configuration says. Warnings about variables that are
// ignored go to stderr. `domain`: the explicit id (--domain), or kDomainFromEnvironment; `node`:
// the node it is.
Result<Participant> create_dds_participant(std::uint32_t domain = kDomainFromEnvironment,
                                           const NodeName& node = {});

// The loopback configuration compiled into rbsim (node/config/cyclonedds-loopback.xml).
std::string_view loopback_config();

// ---------------------------------------------------------------------------------------------
// DDS's side of the handles, for tests, benchmarks and diagnostics: 0 (or empty) for a handle of
// another middleware.
std::int32_t dds_entity(const Participant& participant);
std::int32_t dds_entity(const Publisher& publisher);        // its writer
std::int32_t dds_entity(const Subscription& subscription);  // its reader
std::uint32_t dds_domain(const Participant& participant);
RosDistro dds_distro(const Participant& participant);

// ---------------------------------------------------------------------------------------------
// Services on the wire

inline constexpr std::size_t kRequestHeaderBytes = 16;

// "/rbsim/pause" -> "rq/rbsim/pauseRequest" and "rr/rbsim/pauseReply".
std::string service_request_topic(std::string_view service);
std::string service_reply_topic(std::string_view service);
// "std_srvs/srv/Trigger" -> "std_srvs::srv::dds_::Trigger_Request_" and "..._Response_".
std::string service_request_type(std::string_view srv_type);
std::string service_response_type(std::string_view srv_type);

// A service sample: `header` then the fields of `body` (a CDR message with its encapsulation
// header, as msgs' encoders write it) into `out` (replaced).
void wrap_service_sample(const RequestHeader& header, std::span<const std::byte> body, Bytes& out);
// The header of a service sample, and its fields as a CDR message of their own (encapsulation
// header included) in `body` (replaced). Fails when the sample is not plain little-endian CDR or is
// too short to hold the header.
Result<RequestHeader> unwrap_service_sample(std::span<const std::byte> sample, Bytes& body);

// How another participant knows one of our endpoints: its DDS GUID (prefix and entity id, the
// Jazzy GID; Humble pads it to 24 bytes) and, inside this process, its instance handle.
struct EndpointId {
  std::array<std::uint8_t, 16> guid{};
  std::uint64_t instance_handle = 0;
};
EndpointId dds_request_reader(const ServiceServer& server);
EndpointId dds_reply_writer(const ServiceServer& server);
EndpointId dds_request_writer(const ServiceClient& client);
EndpointId dds_reply_reader(const ServiceClient& client);

// What a service's endpoints add to their USER_DATA after "serviceid=<id>;" / "clientid=<id>;"
// and, for a node's endpoint (in_graph), its "typehash=RIHS01_...;".
struct DdsServiceUserData {
  std::string request, reply;
};
Result<ServiceServer> create_dds_server(const Participant& participant, std::string_view service,
                                        std::string_view srv_type, const ServiceOptions& options,
                                        const DdsServiceUserData& user_data);
Result<ServiceClient> create_dds_client(const Participant& participant, std::string_view service,
                                        std::string_view srv_type, const ClientOptions& options,
                                        const DdsServiceUserData& user_data);

}  // namespace rbsim::node
