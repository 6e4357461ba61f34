// ROS 2 service and parameter interfaces as plain structs with CDR codecs: rcl_interfaces' parameter
// messages and its six parameter services, std_srvs/srv/Trigger, rbsim_msgs' Step and
// ApplyImpulse services, and rosbag2_interfaces' player services. Field order and types follow the .msg/.srv
// definitions (ros2/rcl_interfaces, ros2/common_interfaces, tools/msgs/definitions); the bytes are those of
// msgs.hpp's CDR (XCDR1, little endian, 4-byte encapsulation header), the body of a service sample without
// the request header rmw_cyclonedds_cpp puts before it (node/dds/include/rbsim/dds.hpp adds and strips
// that).
//
// decode() reads untrusted bytes: a truncated message, a length that runs past the data or a wrong
// encapsulation header is an error naming the type and the byte offset, never a crash; every
// sequence length is checked against the bytes left before anything is allocated, so memory stays
// proportional to the input.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "rbsim/msgs.hpp"

namespace rbsim::msgs {

// rcl_interfaces/msg/ParameterType: the values of ParameterValue::type.
enum class ParameterType : std::uint8_t {
  NotSet = 0,
  Bool = 1,
  Integer = 2,
  Double = 3,
  String = 4,
  ByteArray = 5,
  BoolArray = 6,
  IntegerArray = 7,
  DoubleArray = 8,
  StringArray = 9,
};

// rcl_interfaces/msg/ParameterValue: `type` says which field holds the value (other values are
// carried as received: a reader checks it).
struct ParameterValue {
  static constexpr std::string_view kType = "rcl_interfaces/msg/ParameterValue";
  ParameterType type = ParameterType::NotSet;
  bool bool_value = false;
  std::int64_t integer_value = 0;
  double double_value = 0.0;
  std::string string_value;
  std::vector<std::uint8_t> byte_array_value;
  std::vector<bool> bool_array_value;
  std::vector<std::int64_t> integer_array_value;
  std::vector<double> double_array_value;
  std::vector<std::string> string_array_value;
  static ParameterValue of_bool(bool v);
  static ParameterValue of_integer(std::int64_t v);
  static ParameterValue of_double(double v);
  static ParameterValue of_string(std::string v);
  bool operator==(const ParameterValue&) const = default;
};
struct Parameter {
  static constexpr std::string_view kType = "rcl_interfaces/msg/Parameter";
  std::string name;
  ParameterValue value;
  bool operator==(const Parameter&) const = default;
};
struct FloatingPointRange {
  double from_value = 0.0, to_value = 0.0, step = 0.0;
  bool operator==(const FloatingPointRange&) const = default;
};
struct IntegerRange {
  std::int64_t from_value = 0, to_value = 0;
  std::uint64_t step = 0;
  bool operator==(const IntegerRange&) const = default;
};
// rcl_interfaces/msg/ParameterDescriptor; the ranges are bounded sequences of at most one element
// (FloatingPointRange[<=1]), here an optional (more than one on the wire is a decode error).
struct ParameterDescriptor {
  static constexpr std::string_view kType = "rcl_interfaces/msg/ParameterDescriptor";
  std::string name;
  ParameterType type = ParameterType::NotSet;
  std::string description, additional_constraints;
  bool read_only = false, dynamic_typing = false;
  std::optional<FloatingPointRange> floating_point_range;
  std::optional<IntegerRange> integer_range;
  bool operator==(const ParameterDescriptor&) const = default;
};
struct SetParametersResult {
  static constexpr std::string_view kType = "rcl_interfaces/msg/SetParametersResult";
  bool successful = false;
  std::string reason;
  bool operator==(const SetParametersResult&) const = default;
};
struct ListParametersResult {
  static constexpr std::string_view kType = "rcl_interfaces/msg/ListParametersResult";
  std::vector<std::string> names, prefixes;
  bool operator==(const ListParametersResult&) const = default;
};
// rcl_interfaces/msg/ParameterEvent (/parameter_events): `node` is the fully qualified node name.
struct ParameterEvent {
  static constexpr std::string_view kType = "rcl_interfaces/msg/ParameterEvent";
  Time stamp;
  std::string node;
  std::vector<Parameter> new_parameters, changed_parameters, deleted_parameters;
  bool operator==(const ParameterEvent&) const = default;
};

// rbsim_msgs/msg/Command (/<ns>/commands): one control input as data, with its outcome.
struct CommandMessage {
  static constexpr std::string_view kType = "rbsim_msgs/msg/Command";
  static constexpr std::string_view kSuffix = "commands";  // /<ns>/commands
  enum Kind : std::uint8_t {
    SetParameters = 0,
    Pause = 1,
    Resume = 2,
    Step = 3,
    Reset = 4,
    ApplyImpulse = 5,
    // Not a constant of Command.msg (whose text recordings are checked against): set_entity_state,
    // its values in `parameters` (x, y, theta; vx, vy, omega) and its body in `body`.
    SetEntityState = 6,
    // Not a constant of Command.msg either: stop_stepping (a SimulateSteps cancel), no arguments.
    StopStepping = 7,
    // Nor these, the living world's: spawn_entity (its arguments as named parameters: the
    // fragment's text `resource`, `uri`, `name`, `allow_renaming`, the pose `x`, `y`, `theta`),
    // delete_entity (`name`) and reset_spawned (none); load_world (the scene's text `resource`, its
    // `uri`) and unload_world (none).
    SpawnEntity = 8,
    DeleteEntity = 9,
    ResetSpawned = 10,
    LoadWorld = 11,
    UnloadWorld = 12
  };
  std::uint64_t seq = 0;  // the sequence number (`sequence` is an IDL keyword)
  std::uint64_t step = 0;
  Time stamp;
  std::uint8_t kind = SetParameters;  // as received: a reader checks it
  std::string source;
  std::vector<Parameter> parameters;
  bool atomic = true;
  std::uint64_t steps = 0;
  double pause_seconds = 0.0;
  std::uint32_t body = 0;
  double jx = 0.0, jy = 0.0, px = 0.0, py = 0.0;
  bool success = false;
  std::string message;
  bool operator==(const CommandMessage&) const = default;
};

// ---------------------------------------------------------------------------------------------
// Services: kService is the service type ("pkg/srv/Name"), each half its own struct.

struct ListParametersRequest {
  static constexpr std::string_view kService = "rcl_interfaces/srv/ListParameters";
  static constexpr std::uint64_t kDepthRecursive = 0;
  std::vector<std::string> prefixes;
  std::uint64_t depth = kDepthRecursive;
  bool operator==(const ListParametersRequest&) const = default;
};
struct ListParametersResponse {
  static constexpr std::string_view kService = ListParametersRequest::kService;
  ListParametersResult result;
  bool operator==(const ListParametersResponse&) const = default;
};
struct GetParametersRequest {
  static constexpr std::string_view kService = "rcl_interfaces/srv/GetParameters";
  std::vector<std::string> names;
  bool operator==(const GetParametersRequest&) const = default;
};
struct GetParametersResponse {
  static constexpr std::string_view kService = GetParametersRequest::kService;
  std::vector<ParameterValue> values;
  bool operator==(const GetParametersResponse&) const = default;
};
struct SetParametersRequest {
  static constexpr std::string_view kService = "rcl_interfaces/srv/SetParameters";
  std::vector<Parameter> parameters;
  bool operator==(const SetParametersRequest&) const = default;
};
struct SetParametersResponse {
  static constexpr std::string_view kService = SetParametersRequest::kService;
  std::vector<SetParametersResult> results;
  bool operator==(const SetParametersResponse&) const = default;
};
struct SetParametersAtomicallyRequest {
  static constexpr std::string_view kService = "rcl_interfaces/srv/SetParametersAtomically";
  std::vector<Parameter> parameters;
  bool operator==(const SetParametersAtomicallyRequest&) const = default;
};
struct SetParametersAtomicallyResponse {
  static constexpr std::string_view kService = SetParametersAtomicallyRequest::kService;
  SetParametersResult result;
  bool operator==(const SetParametersAtomicallyResponse&) const = default;
};
struct DescribeParametersRequest {
  static constexpr std::string_view kService = "rcl_interfaces/srv/DescribeParameters";
  std::vector<std::string> names;
  bool operator==(const DescribeParametersRequest&) const = default;
};
struct DescribeParametersResponse {
  static constexpr std::string_view kService = DescribeParametersRequest::kService;
  std::vector<ParameterDescriptor> descriptors;
  bool operator==(const DescribeParametersResponse&) const = default;
};
struct GetParameterTypesRequest {
  static constexpr std::string_view kService = "rcl_interfaces/srv/GetParameterTypes";
  std::vector<std::string> names;
  bool operator==(const GetParameterTypesRequest&) const = default;
};
struct GetParameterTypesResponse {
  static constexpr std::string_view kService = GetParameterTypesRequest::kService;
  std::vector<std::uint8_t> types;
  bool operator==(const GetParameterTypesResponse&) const = default;
};
// std_srvs/srv/Trigger. Its request has no fields: on the wire it is rosidl's one placeholder
// member, `uint8 structure_needs_at_least_one_member` (written 0, read and ignored).
struct TriggerRequest {
  static constexpr std::string_view kService = "std_srvs/srv/Trigger";
  bool operator==(const TriggerRequest&) const = default;
};
struct TriggerResponse {
  static constexpr std::string_view kService = TriggerRequest::kService;
  bool success = false;
  std::string message;
  bool operator==(const TriggerResponse&) const = default;
};
// rbsim_msgs/srv/Step: `steps` steps while paused.
struct StepRequest {
  static constexpr std::string_view kService = "rbsim_msgs/srv/Step";
  std::uint32_t steps = 0;
  bool operator==(const StepRequest&) const = default;
};
// The reply of Step and ApplyImpulse: `step` is the step the change shows at.
struct StepResponse {
  static constexpr std::string_view kService = StepRequest::kService;
  bool success = false;
  std::string message;
  std::uint64_t step = 0;
  bool operator==(const StepResponse&) const = default;
};
// rbsim_msgs/srv/ApplyImpulse: linear impulse (jx, jy) in world axes at the point (px, py) in the
// body frame, relative to the centre of mass.
struct ApplyImpulseRequest {
  static constexpr std::string_view kService = "rbsim_msgs/srv/ApplyImpulse";
  std::uint32_t body = 0;
  double jx = 0.0, jy = 0.0, px = 0.0, py = 0.0;
  bool operator==(const ApplyImpulseRequest&) const = default;
};
struct ApplyImpulseResponse {
  static constexpr std::string_view kService = ApplyImpulseRequest::kService;
  bool success = false;
  std::string message;
  std::uint64_t step = 0;
  bool operator==(const ApplyImpulseResponse&) const = default;
};

// rosbag2_interfaces (Jazzy): the player's services (rbsim replay's /rbsim_player/...). A half with
// no fields is rosidl's one placeholder member on the wire, as TriggerRequest.
#define RBSIM_EMPTY_HALF(Name, service)                   \
  struct Name {                                           \
    static constexpr std::string_view kService = service; \
    bool operator==(const Name&) const = default;         \
  };
RBSIM_EMPTY_HALF(PauseRequest, "rosbag2_interfaces/srv/Pause")
RBSIM_EMPTY_HALF(PauseResponse, "rosbag2_interfaces/srv/Pause")
RBSIM_EMPTY_HALF(ResumeRequest, "rosbag2_interfaces/srv/Resume")
RBSIM_EMPTY_HALF(ResumeResponse, "rosbag2_interfaces/srv/Resume")
RBSIM_EMPTY_HALF(TogglePausedRequest, "rosbag2_interfaces/srv/TogglePaused")
RBSIM_EMPTY_HALF(TogglePausedResponse, "rosbag2_interfaces/srv/TogglePaused")
RBSIM_EMPTY_HALF(IsPausedRequest, "rosbag2_interfaces/srv/IsPaused")
RBSIM_EMPTY_HALF(GetRateRequest, "rosbag2_interfaces/srv/GetRate")
RBSIM_EMPTY_HALF(PlayNextRequest, "rosbag2_interfaces/srv/PlayNext")
RBSIM_EMPTY_HALF(SnapshotRequest, "rosbag2_interfaces/srv/Snapshot")
RBSIM_EMPTY_HALF(SplitBagfileRequest, "rosbag2_interfaces/srv/SplitBagfile")
RBSIM_EMPTY_HALF(SplitBagfileResponse, "rosbag2_interfaces/srv/SplitBagfile")
#undef RBSIM_EMPTY_HALF
// The recorder's (rbsim record's /rbsim_recorder/...): snapshot, split_bagfile, and the player's
// pause, resume and is_paused types.
struct SnapshotResponse {
  static constexpr std::string_view kService = SnapshotRequest::kService;
  bool success = false;
  bool operator==(const SnapshotResponse&) const = default;
};
struct IsPausedResponse {
  static constexpr std::string_view kService = IsPausedRequest::kService;
  bool paused = false;
  bool operator==(const IsPausedResponse&) const = default;
};
struct GetRateResponse {
  static constexpr std::string_view kService = GetRateRequest::kService;
  double rate = 0.0;
  bool operator==(const GetRateResponse&) const = default;
};
struct SetRateRequest {
  static constexpr std::string_view kService = "rosbag2_interfaces/srv/SetRate";
  double rate = 0.0;
  bool operator==(const SetRateRequest&) const = default;
};
struct SetRateResponse {
  static constexpr std::string_view kService = SetRateRequest::kService;
  bool success = false;  // a rate > 0 was set
  bool operator==(const SetRateResponse&) const = default;
};
struct SeekRequest {
  static constexpr std::string_view kService = "rosbag2_interfaces/srv/Seek";
  Time time;  // builtin_interfaces/Time
  bool operator==(const SeekRequest& o) const {
    return time.sec == o.time.sec && time.nanosec == o.time.nanosec;
  }
};
struct SeekResponse {
  static constexpr std::string_view kService = SeekRequest::kService;
  bool success = false;
  bool operator==(const SeekResponse&) const = default;
};
struct PlayNextResponse {
  static constexpr std::string_view kService = PlayNextRequest::kService;
  bool success = false;  // only while paused
  bool operator==(const PlayNextResponse&) const = default;
};
struct BurstRequest {
  static constexpr std::string_view kService = "rosbag2_interfaces/srv/Burst";
  std::uint64_t num_messages = 0;  // 0: the rest of the log
  bool operator==(const BurstRequest&) const = default;
};
struct BurstResponse {
  static constexpr std::string_view kService = BurstRequest::kService;
  std::uint64_t actually_burst = 0;
  bool operator==(const BurstResponse&) const = default;
};

// ---------------------------------------------------------------------------------------------
// Actions (Jazzy's action_msgs and unique_identifier_msgs): what every ROS 2 action carries beside
// its own goal, result and feedback, whatever the action. rosidl makes of an action "pkg/action/X"
// the services X_SendGoal (request: goal id, then the goal; response: SendGoalResponse) and
// X_GetResult (request: GetResultRequest; response: status, then the result) and the message
// X_FeedbackMessage (goal id, then the feedback); the action's own halves are in its package's
// header (rbsim/simulation_interfaces.hpp).

using GoalUuid = std::array<std::uint8_t, 16>;  // unique_identifier_msgs/msg/UUID
// action_msgs/msg/GoalInfo: the goal's id and when the server accepted it.
struct GoalInfo {
  GoalUuid goal_id{};
  Time stamp;
  bool operator==(const GoalInfo&) const = default;
};
// action_msgs/msg/GoalStatus.
struct GoalStatus {
  static constexpr std::int8_t kUnknown = 0;
  static constexpr std::int8_t kAccepted = 1;
  static constexpr std::int8_t kExecuting = 2;
  static constexpr std::int8_t kCanceling = 3;
  static constexpr std::int8_t kSucceeded = 4;
  static constexpr std::int8_t kCanceled = 5;
  static constexpr std::int8_t kAborted = 6;
  GoalInfo goal_info;
  std::int8_t status = kUnknown;
  bool operator==(const GoalStatus&) const = default;
};
// action_msgs/msg/GoalStatusArray: an action's <action>/_action/status topic.
struct GoalStatusArray {
  static constexpr std::string_view kType = "action_msgs/msg/GoalStatusArray";
  std::vector<GoalStatus> status_list;
  bool operator==(const GoalStatusArray&) const = default;
};
// action_msgs/srv/CancelGoal: a zero goal id and a zero stamp cancel every goal; a zero id and a
// stamp, every goal accepted at or before it; an id, that goal (and, with a stamp, every goal
// accepted at or before it too).
struct CancelGoalRequest {
  static constexpr std::string_view kService = "action_msgs/srv/CancelGoal";
  GoalInfo goal_info;
  bool operator==(const CancelGoalRequest&) const = default;
};
struct CancelGoalResponse {
  static constexpr std::string_view kService = CancelGoalRequest::kService;
  static constexpr std::int8_t kErrorNone = 0;
  static constexpr std::int8_t kErrorRejected = 1;
  static constexpr std::int8_t kErrorUnknownGoalId = 2;
  static constexpr std::int8_t kErrorGoalTerminated = 3;
  std::int8_t return_code = kErrorNone;
  std::vector<GoalInfo> goals_canceling;
  bool operator==(const CancelGoalResponse&) const = default;
};
// Every action's SendGoal response and GetResult request (the same fields for any action).
struct SendGoalResponse {
  static constexpr std::string_view kType = "<action>_SendGoal_Response";
  bool accepted = false;
  Time stamp;
  bool operator==(const SendGoalResponse&) const = default;
};
struct GetResultRequest {
  static constexpr std::string_view kType = "<action>_GetResult_Request";
  GoalUuid goal_id{};
  bool operator==(const GetResultRequest&) const = default;
};
// The goal id that begins every action request (SendGoal's and GetResult's), read from its CDR.
[[nodiscard]] Result<GoalUuid> request_goal_id(std::span<const std::byte> cdr);

// ---------------------------------------------------------------------------------------------
// Codecs: encode() replaces `out` with the message's CDR (encapsulation header included);
// decode() fills `out` (replaced whole) or fails naming the type and the offset, `out` then
// unspecified.

#define RBSIM_INTERFACE_CODEC(T)             \
  void encode(const T& message, Bytes& out); \
  [[nodiscard]] Status decode(std::span<const std::byte> cdr, T& out);
RBSIM_INTERFACE_CODEC(ParameterValue)
RBSIM_INTERFACE_CODEC(Parameter)
RBSIM_INTERFACE_CODEC(ParameterDescriptor)
RBSIM_INTERFACE_CODEC(SetParametersResult)
RBSIM_INTERFACE_CODEC(ListParametersResult)
RBSIM_INTERFACE_CODEC(ParameterEvent)
RBSIM_INTERFACE_CODEC(CommandMessage)
RBSIM_INTERFACE_CODEC(ListParametersRequest)
RBSIM_INTERFACE_CODEC(ListParametersResponse)
RBSIM_INTERFACE_CODEC(GetParametersRequest)
RBSIM_INTERFACE_CODEC(GetParametersResponse)
RBSIM_INTERFACE_CODEC(SetParametersRequest)
RBSIM_INTERFACE_CODEC(SetParametersResponse)
RBSIM_INTERFACE_CODEC(SetParametersAtomicallyRequest)
RBSIM_INTERFACE_CODEC(SetParametersAtomicallyResponse)
RBSIM_INTERFACE_CODEC(DescribeParametersRequest)
RBSIM_INTERFACE_CODEC(DescribeParametersResponse)
RBSIM_INTERFACE_CODEC(GetParameterTypesRequest)
RBSIM_INTERFACE_CODEC(GetParameterTypesResponse)
RBSIM_INTERFACE_CODEC(TriggerRequest)
RBSIM_INTERFACE_CODEC(TriggerResponse)
RBSIM_INTERFACE_CODEC(StepRequest)
RBSIM_INTERFACE_CODEC(StepResponse)
RBSIM_INTERFACE_CODEC(ApplyImpulseRequest)
RBSIM_INTERFACE_CODEC(ApplyImpulseResponse)
RBSIM_INTERFACE_CODEC(PauseRequest)
RBSIM_INTERFACE_CODEC(PauseResponse)
RBSIM_INTERFACE_CODEC(ResumeRequest)
RBSIM_INTERFACE_CODEC(ResumeResponse)
RBSIM_INTERFACE_CODEC(TogglePausedRequest)
RBSIM_INTERFACE_CODEC(TogglePausedResponse)
RBSIM_INTERFACE_CODEC(IsPausedRequest)
RBSIM_INTERFACE_CODEC(IsPausedResponse)
RBSIM_INTERFACE_CODEC(GetRateRequest)
RBSIM_INTERFACE_CODEC(GetRateResponse)
RBSIM_INTERFACE_CODEC(SetRateRequest)
RBSIM_INTERFACE_CODEC(SetRateResponse)
RBSIM_INTERFACE_CODEC(SeekRequest)
RBSIM_INTERFACE_CODEC(SeekResponse)
RBSIM_INTERFACE_CODEC(PlayNextRequest)
RBSIM_INTERFACE_CODEC(PlayNextResponse)
RBSIM_INTERFACE_CODEC(BurstRequest)
RBSIM_INTERFACE_CODEC(BurstResponse)
RBSIM_INTERFACE_CODEC(SnapshotRequest)
RBSIM_INTERFACE_CODEC(SnapshotResponse)
RBSIM_INTERFACE_CODEC(SplitBagfileRequest)
RBSIM_INTERFACE_CODEC(SplitBagfileResponse)
RBSIM_INTERFACE_CODEC(GoalStatusArray)
RBSIM_INTERFACE_CODEC(CancelGoalRequest)
RBSIM_INTERFACE_CODEC(CancelGoalResponse)
RBSIM_INTERFACE_CODEC(SendGoalResponse)
RBSIM_INTERFACE_CODEC(GetResultRequest)
#undef RBSIM_INTERFACE_CODEC

}  // namespace rbsim::msgs
