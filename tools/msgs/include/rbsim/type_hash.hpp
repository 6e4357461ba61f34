// REP 2011 type hashes ("RIHS01_<64 hex>") of ROS 2 interface types, computed from the .msg, .srv
// and .action definitions (never written down by hand): what rmw_cyclonedds_cpp on Jazzy puts in every
// endpoint's USER_DATA ("typehash=RIHS01_...;") and rosbag2 records per topic.
//
// The hash is rosidl's (rosidl_generator_type_description; rcl computes the same at run time): the
// type_description_interfaces/TypeDescription of the type (rbsim/type_description.hpp: its fields'
// type ids, array capacities, string bounds and nested type names; default values left out) and
// of every type it refers to, directly or not, sorted by name, written as JSON with Python's
// json.dumps separators (", " and ": ", no newlines) and hashed with SHA-256.
//
// Type names are fully qualified: "std_msgs/msg/String", a service "std_srvs/srv/Trigger", or one
// of the messages rosidl makes of a service: "std_srvs/srv/Trigger_Request", "..._Response" and
// "..._Event" (service_msgs/msg/ServiceEventInfo info, the request and the response each as a
// sequence of at most one).
//
// An action "pkg/action/Name" is what rosidl_parser's Action makes of the .action text (goal,
// result and feedback split by two "---" lines): "pkg/action/Name_Goal", "..._Result" and
// "..._Feedback" (the three parts), the services "..._SendGoal" (request: UUID goal_id, _Goal goal;
// response: bool accepted, builtin_interfaces/Time stamp) and "..._GetResult" (request: goal_id;
// response: int8 status, _Result result), each with its _Request, _Response and _Event, and
// "..._FeedbackMessage" (goal_id, _Feedback feedback); the action type itself refers to those six
// (goal, result, feedback, send_goal_service, get_result_service, feedback_message), as
// rosidl_generator_type_description's add_action describes it. goal_id is
// unique_identifier_msgs/msg/UUID.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "rbsim/status.hpp"
#include "rbsim/type_description.hpp"

namespace rbsim::msgs {

// Where definitions come from: the .msg text of "pkg/msg/Name", the .srv text of "pkg/srv/Name" or
// the .action text of "pkg/action/Name";
// nullopt when unknown (an empty text is a message without fields, as std_msgs/msg/Empty).
using DefinitionSource = std::function<std::optional<std::string_view>(std::string_view type)>;
// The definitions rbsim ships (msgs::definition(), none of them empty).
std::optional<std::string_view> shipped_definition(std::string_view type);

// The type description of `type`: the one structured description both the hash and the
// ~/get_type_description reply come from. Field.default_value is rosidl's spelling of the .msg
// default (str() of the Python value rosidl_parser reads: "0.0", "1", "True", "(1, 2)", a string
// without its quotes; empty when none), as rosidl_generator_type_description fills it and rclcpp's
// service returns it. Fails, naming the type, on an unknown type, a missing dependency, a
// malformed definition or default value, a service without exactly one "---" or an action
// without exactly two.
Result<TypeDescription> type_description(std::string_view type, const DefinitionSource& source);
Result<TypeDescription> type_description(std::string_view type);  // over shipped_definition()
// The JSON the hash is taken over: the description with its default values left out.
std::string type_description_json(const TypeDescription& description);
Result<std::string> type_description_json(std::string_view type, const DefinitionSource& source);
// "RIHS01_" + the SHA-256 of type_description_json() in lower-case hex.
Result<std::string> type_hash(const TypeDescription& description);
Result<std::string> type_hash(std::string_view type, const DefinitionSource& source);
// The same over shipped_definition(); each hash is computed once per
// process and then served from a cache (thread-safe).
Result<std::string> type_hash(std::string_view type);

// The hashes rmw_cyclonedds_cpp (Jazzy) puts in the USER_DATA of a service's two endpoints: the
// request topic's (rq/...Request: the service's reader, a client's writer) carries the hash of
// "<service>_Request", the reply topic's (rr/...Reply) that of "<service>_Response"; neither carries
// the service type's own hash (create_cdds_client / create_cdds_service in rmw_node.cpp take them
// from the request and response type supports). `service` is "pkg/srv/Name"; shipped definitions,
// cached as type_hash() is.
struct ServiceEndpointHashes {
  std::string request;  // rq/<service name>Request
  std::string reply;    // rr/<service name>Reply
};
Result<ServiceEndpointHashes> service_endpoint_type_hashes(std::string_view service);

// The texts the types of `description` were defined in, as rosidl_generator_c embeds them (its
// get_type_description_sources): the described type first, then each referenced type in the
// description's order. A type with a definition of its own has encoding "msg", "srv" or
// "action" and the file's text (its lines joined by "\n", without the final newline); one rosidl
// derives from a service or an action (_Request, _Response, _Event, an action's parts) has
// encoding "implicit" and no text.
std::vector<TypeSource> type_sources(const TypeDescription& description, const DefinitionSource& source);

// The USER_DATA entry of an endpoint as rmw_dds_common writes it: "typehash=" + hash + ";". An
// endpoint's USER_DATA is rmw_cyclonedds's extra entries first ("serviceid=...;" or
// "clientid=...;" for services), then this.
std::string typehash_user_data(std::string_view hash);

}  // namespace rbsim::msgs
