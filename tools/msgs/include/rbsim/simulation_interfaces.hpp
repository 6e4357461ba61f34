// simulation_interfaces 2.1.0 (ros-simulation/simulation_interfaces, the ROS 2 standard simulator
// interfaces Gazebo, Isaac Sim and O3DE serve) as plain structs with CDR codecs: the messages and
// the services rbsim node serves, and those of spawning, deleting and worlds (the .msg/.srv text
// is in tools/msgs/definitions/simulation_interfaces, their type hashes come from there; the
// names are kType and kService). Field order and types follow those definitions; the bytes are
// msgs.hpp's CDR, as rbsim/interfaces.hpp's codecs write them, and decode() reads untrusted bytes
// with the same checks (every length against the bytes left before anything is allocated; an
// error names the type and the byte offset).
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "rbsim/interfaces.hpp"
#include "rbsim/msgs.hpp"

namespace rbsim::msgs::simulation {

// simulation_interfaces/msg/Result: `result` is one of these, or a service's own code (>= 101).
struct Result {
  static constexpr std::string_view kType = "simulation_interfaces/msg/Result";
  static constexpr std::uint8_t kFeatureUnsupported = 0;
  static constexpr std::uint8_t kOk = 1;
  static constexpr std::uint8_t kNotFound = 2;
  static constexpr std::uint8_t kIncorrectState = 3;
  static constexpr std::uint8_t kOperationFailed = 4;
  std::uint8_t result = kFeatureUnsupported;
  std::string error_message;
  bool operator==(const Result&) const = default;
};

// simulation_interfaces/msg/SimulatorFeatures' constants (what `features` lists).
enum class Feature : std::uint16_t {
  Spawning = 0,
  Deleting = 1,
  NamedPoses = 2,
  PoseBounds = 3,
  EntityTags = 4,
  EntityBounds = 5,
  EntityBoundsBox = 6,
  EntityBoundsConvex = 7,
  EntityCategories = 8,
  SpawningResourceString = 9,
  EntityStateGetting = 10,
  EntityStateSetting = 11,
  EntityInfoGetting = 12,
  EntityInfoSetting = 13,
  Spawnables = 14,
  SimulationReset = 20,
  SimulationResetTime = 21,
  SimulationResetState = 22,
  SimulationResetSpawned = 23,
  SimulationStateGetting = 24,
  SimulationStateSetting = 25,
  SimulationStatePause = 26,
  StepSimulationSingle = 31,
  StepSimulationMultiple = 32,
  StepSimulationAction = 33,
  WorldLoading = 40,
  WorldResourceString = 41,
  WorldTags = 42,
  WorldUnloading = 43,
  WorldInfoGetting = 44,
  AvailableWorlds = 45,
  SpawningEntities = 50,
};

struct SimulatorFeatures {
  static constexpr std::string_view kType = "simulation_interfaces/msg/SimulatorFeatures";
  std::vector<std::uint16_t> features;
  std::vector<std::string> spawn_formats;
  std::string custom_info;
  bool operator==(const SimulatorFeatures&) const = default;
};

// simulation_interfaces/msg/SimulationState's values.
enum class State : std::uint8_t {
  Stopped = 0,
  Playing = 1,
  Paused = 2,
  Quitting = 3,
  NoWorld = 4,
  LoadingWorld = 5
};

// simulation_interfaces/msg/EntityCategory's values.
enum class Category : std::uint8_t { Object = 0, Robot = 1, Human = 2, DynamicObject = 4, StaticObject = 5 };

// simulation_interfaces/msg/Bounds' types.
enum class BoundsType : std::uint8_t { Empty = 0, Box = 1, ConvexHull = 2, Sphere = 3 };

// geometry_msgs/msg/Vector3 (and Point, the same fields).
struct Vector3 {
  double x = 0.0, y = 0.0, z = 0.0;
  bool operator==(const Vector3&) const = default;
};

// simulation_interfaces/msg/Bounds: TYPE_BOX has two points (the corners), TYPE_SPHERE the centre
// and a point whose x is the radius, TYPE_CONVEX_HULL three or more. `type` as received.
struct Bounds {
  static constexpr std::string_view kType = "simulation_interfaces/msg/Bounds";
  std::uint8_t type = static_cast<std::uint8_t>(BoundsType::Empty);
  std::vector<Vector3> points;
  bool operator==(const Bounds&) const = default;
};

// simulation_interfaces/msg/TagsFilter.
struct TagsFilter {
  static constexpr std::uint8_t kFilterModeAny = 0;
  static constexpr std::uint8_t kFilterModeAll = 1;
  std::vector<std::string> tags;
  std::uint8_t filter_mode = kFilterModeAny;  // as received
  bool operator==(const TagsFilter&) const = default;
};

// simulation_interfaces/msg/EntityFilters: every filter given applies (and); categories as
// received (EntityCategory's values).
struct EntityFilters {
  static constexpr std::string_view kType = "simulation_interfaces/msg/EntityFilters";
  std::string filter;  // POSIX extended regular expression on the name; empty: any
  std::vector<std::uint8_t> categories;
  TagsFilter tags;
  Bounds bounds;
  bool operator==(const EntityFilters&) const = default;
};

// simulation_interfaces/msg/EntityInfo.
struct EntityInfo {
  std::uint8_t category = static_cast<std::uint8_t>(Category::Object);
  std::string description;
  std::vector<std::string> tags;
  bool operator==(const EntityInfo&) const = default;
};

// simulation_interfaces/msg/EntityState: header, geometry_msgs Pose, Twist and Accel.
struct EntityState {
  static constexpr std::string_view kType = "simulation_interfaces/msg/EntityState";
  Time stamp;
  std::string frame_id;
  Vector3 position;
  Quaternion orientation;
  Vector3 linear_velocity, angular_velocity;
  Vector3 linear_acceleration, angular_acceleration;
  bool operator==(const EntityState&) const = default;
};

// geometry_msgs/msg/PoseStamped: header, then the pose (Point position, Quaternion orientation).
struct PoseStamped {
  static constexpr std::string_view kType = "geometry_msgs/msg/PoseStamped";
  Time stamp;
  std::string frame_id;
  Vector3 position;
  Quaternion orientation;
  bool operator==(const PoseStamped&) const = default;
};

// simulation_interfaces/msg/Resource: a URI, or (uri empty) the resource's text itself.
struct Resource {
  static constexpr std::string_view kType = "simulation_interfaces/msg/Resource";
  std::string uri;
  std::string resource_string;
  bool operator==(const Resource&) const = default;
};

// simulation_interfaces/msg/WorldResource: a world LoadWorld loads or GetAvailableWorlds lists.
struct WorldResource {
  static constexpr std::string_view kType = "simulation_interfaces/msg/WorldResource";
  std::string name;
  Resource world_resource;
  std::string description;
  std::vector<std::string> tags;
  bool operator==(const WorldResource&) const = default;
};

// simulation_interfaces/msg/Spawnable: what GetSpawnables lists.
struct Spawnable {
  static constexpr std::string_view kType = "simulation_interfaces/msg/Spawnable";
  Resource entity_resource;
  std::string description;
  Bounds spawn_bounds;
  bool operator==(const Spawnable&) const = default;
};

// simulation_interfaces/msg/SpawnEntity: one entity of a SpawnEntities request (the fields of
// SpawnEntity.srv's request).
struct SpawnEntity {
  static constexpr std::string_view kType = "simulation_interfaces/msg/SpawnEntity";
  std::string name;
  bool allow_renaming = false;
  Resource entity_resource;
  std::string entity_namespace;
  PoseStamped initial_pose;
  bool operator==(const SpawnEntity&) const = default;
};

// simulation_interfaces/msg/SpawnResult: one entity's result in a SpawnEntities response;
// `result.result` one of Result's codes or these (SpawnEntity.srv's response has the same).
struct SpawnResult {
  static constexpr std::string_view kType = "simulation_interfaces/msg/SpawnResult";
  static constexpr std::uint8_t kNameNotUnique = 101;
  static constexpr std::uint8_t kNameInvalid = 102;
  static constexpr std::uint8_t kUnsupportedFormat = 103;
  static constexpr std::uint8_t kNoResource = 104;
  static constexpr std::uint8_t kNamespaceInvalid = 105;
  static constexpr std::uint8_t kResourceParseError = 106;
  static constexpr std::uint8_t kMissingAssets = 107;
  static constexpr std::uint8_t kUnsupportedAssets = 108;
  static constexpr std::uint8_t kInvalidPose = 109;
  Result result;
  std::string entity_name;
  bool operator==(const SpawnResult&) const = default;
};

// ---------------------------------------------------------------------------------------------
// Services: kService is the service type, each half its own struct.

struct GetSimulatorFeaturesRequest {
  static constexpr std::string_view kService = "simulation_interfaces/srv/GetSimulatorFeatures";
};
struct GetSimulatorFeaturesResponse {
  static constexpr std::string_view kService = GetSimulatorFeaturesRequest::kService;
  SimulatorFeatures features;
};
struct GetSimulationStateRequest {
  static constexpr std::string_view kService = "simulation_interfaces/srv/GetSimulationState";
};
struct GetSimulationStateResponse {
  static constexpr std::string_view kService = GetSimulationStateRequest::kService;
  std::uint8_t state = 0;
  Result result;
};
struct SetSimulationStateRequest {
  static constexpr std::string_view kService = "simulation_interfaces/srv/SetSimulationState";
  std::uint8_t state = 0;  // as received
};
struct SetSimulationStateResponse {
  static constexpr std::string_view kService = SetSimulationStateRequest::kService;
  static constexpr std::uint8_t kAlreadyInTargetState = 101;
  static constexpr std::uint8_t kStateTransitionError = 102;
  static constexpr std::uint8_t kIncorrectTransition = 103;
  Result result;
};
struct ResetSimulationRequest {
  static constexpr std::string_view kService = "simulation_interfaces/srv/ResetSimulation";
  static constexpr std::uint8_t kScopeDefault = 0;
  static constexpr std::uint8_t kScopeTime = 1;
  static constexpr std::uint8_t kScopeState = 2;
  static constexpr std::uint8_t kScopeSpawned = 4;
  static constexpr std::uint8_t kScopeAll = 255;
  std::uint8_t scope = kScopeDefault;
};
struct ResetSimulationResponse {
  static constexpr std::string_view kService = ResetSimulationRequest::kService;
  Result result;
};
struct StepSimulationRequest {
  static constexpr std::string_view kService = "simulation_interfaces/srv/StepSimulation";
  std::uint64_t steps = 1;  // the definition's default
};
struct StepSimulationResponse {
  static constexpr std::string_view kService = StepSimulationRequest::kService;
  Result result;
};
struct GetEntitiesRequest {
  static constexpr std::string_view kService = "simulation_interfaces/srv/GetEntities";
  EntityFilters filters;
};
struct GetEntitiesResponse {
  static constexpr std::string_view kService = GetEntitiesRequest::kService;
  Result result;
  std::vector<std::string> entities;
};
struct GetEntitiesStatesRequest {
  static constexpr std::string_view kService = "simulation_interfaces/srv/GetEntitiesStates";
  EntityFilters filters;
};
struct GetEntitiesStatesResponse {
  static constexpr std::string_view kService = GetEntitiesStatesRequest::kService;
  Result result;
  std::vector<std::string> entities;
  std::vector<EntityState> states;
};
struct GetEntityInfoRequest {
  static constexpr std::string_view kService = "simulation_interfaces/srv/GetEntityInfo";
  std::string entity;
};
struct GetEntityInfoResponse {
  static constexpr std::string_view kService = GetEntityInfoRequest::kService;
  Result result;
  EntityInfo info;
};
struct GetEntityStateRequest {
  static constexpr std::string_view kService = "simulation_interfaces/srv/GetEntityState";
  std::string entity;
};
struct GetEntityStateResponse {
  static constexpr std::string_view kService = GetEntityStateRequest::kService;
  Result result;
  EntityState state;
};
struct SetEntityStateRequest {
  static constexpr std::string_view kService = "simulation_interfaces/srv/SetEntityState";
  std::string entity;
  EntityState state;
  bool set_pose = false, set_twist = false, set_acceleration = false;
};
struct SetEntityStateResponse {
  static constexpr std::string_view kService = SetEntityStateRequest::kService;
  static constexpr std::uint8_t kInvalidPose = 101;
  Result result;
};
struct GetEntityBoundsRequest {
  static constexpr std::string_view kService = "simulation_interfaces/srv/GetEntityBounds";
  std::string entity;
};
struct GetEntityBoundsResponse {
  static constexpr std::string_view kService = GetEntityBoundsRequest::kService;
  Result result;
  Bounds bounds;
};

// Spawning, deleting and worlds (the halves compare whole: operator==).
struct SpawnEntityRequest {
  static constexpr std::string_view kService = "simulation_interfaces/srv/SpawnEntity";
  std::string name;
  bool allow_renaming = false;
  Resource entity_resource;
  std::string entity_namespace;
  PoseStamped initial_pose;
  bool operator==(const SpawnEntityRequest&) const = default;
};
struct SpawnEntityResponse {
  static constexpr std::string_view kService = SpawnEntityRequest::kService;
  // The .srv's codes, the values of SpawnResult's.
  static constexpr std::uint8_t kNameNotUnique = SpawnResult::kNameNotUnique;
  static constexpr std::uint8_t kNameInvalid = SpawnResult::kNameInvalid;
  static constexpr std::uint8_t kUnsupportedFormat = SpawnResult::kUnsupportedFormat;
  static constexpr std::uint8_t kNoResource = SpawnResult::kNoResource;
  static constexpr std::uint8_t kNamespaceInvalid = SpawnResult::kNamespaceInvalid;
  static constexpr std::uint8_t kResourceParseError = SpawnResult::kResourceParseError;
  static constexpr std::uint8_t kMissingAssets = SpawnResult::kMissingAssets;
  static constexpr std::uint8_t kUnsupportedAssets = SpawnResult::kUnsupportedAssets;
  static constexpr std::uint8_t kInvalidPose = SpawnResult::kInvalidPose;
  Result result;
  std::string entity_name;
  bool operator==(const SpawnEntityResponse&) const = default;
};
struct SpawnEntitiesRequest {
  static constexpr std::string_view kService = "simulation_interfaces/srv/SpawnEntities";
  std::vector<SpawnEntity> spawn_requests;
  bool operator==(const SpawnEntitiesRequest&) const = default;
};
struct SpawnEntitiesResponse {
  static constexpr std::string_view kService = SpawnEntitiesRequest::kService;
  static constexpr std::uint8_t kEntitiesSpawnFailed = 150;
  Result result;
  std::vector<SpawnResult> results;  // one per request, in order
  bool operator==(const SpawnEntitiesResponse&) const = default;
};
struct DeleteEntityRequest {
  static constexpr std::string_view kService = "simulation_interfaces/srv/DeleteEntity";
  std::string entity;
  bool operator==(const DeleteEntityRequest&) const = default;
};
struct DeleteEntityResponse {  // no codes of its own
  static constexpr std::string_view kService = DeleteEntityRequest::kService;
  Result result;
  bool operator==(const DeleteEntityResponse&) const = default;
};
struct GetSpawnablesRequest {
  static constexpr std::string_view kService = "simulation_interfaces/srv/GetSpawnables";
  std::vector<std::string> sources;
  bool operator==(const GetSpawnablesRequest&) const = default;
};
struct GetSpawnablesResponse {  // no codes of its own
  static constexpr std::string_view kService = GetSpawnablesRequest::kService;
  Result result;
  std::vector<Spawnable> spawnables;
  bool operator==(const GetSpawnablesResponse&) const = default;
};
struct LoadWorldRequest {
  static constexpr std::string_view kService = "simulation_interfaces/srv/LoadWorld";
  Resource world_resource;
  bool fail_on_unsupported_element = false;
  bool ignore_missing_or_unsupported_assets = false;
  bool operator==(const LoadWorldRequest&) const = default;
};
struct LoadWorldResponse {
  static constexpr std::string_view kService = LoadWorldRequest::kService;
  static constexpr std::uint8_t kUnsupportedFormat = 101;
  static constexpr std::uint8_t kNoResource = 102;
  static constexpr std::uint8_t kResourceParseError = 103;
  static constexpr std::uint8_t kMissingAssets = 104;
  static constexpr std::uint8_t kUnsupportedAssets = 105;
  static constexpr std::uint8_t kUnsupportedElements = 106;
  Result result;
  WorldResource world;
  bool operator==(const LoadWorldResponse&) const = default;
};
struct UnloadWorldRequest {
  static constexpr std::string_view kService = "simulation_interfaces/srv/UnloadWorld";
  bool operator==(const UnloadWorldRequest&) const = default;
};
struct UnloadWorldResponse {
  static constexpr std::string_view kService = UnloadWorldRequest::kService;
  static constexpr std::uint8_t kNoWorldLoaded = 101;
  Result result;
  bool operator==(const UnloadWorldResponse&) const = default;
};
struct GetCurrentWorldRequest {
  static constexpr std::string_view kService = "simulation_interfaces/srv/GetCurrentWorld";
  bool operator==(const GetCurrentWorldRequest&) const = default;
};
struct GetCurrentWorldResponse {
  static constexpr std::string_view kService = GetCurrentWorldRequest::kService;
  static constexpr std::uint8_t kNoWorldLoaded = 101;
  Result result;
  WorldResource world;
  bool operator==(const GetCurrentWorldResponse&) const = default;
};
struct GetAvailableWorldsRequest {
  static constexpr std::string_view kService = "simulation_interfaces/srv/GetAvailableWorlds";
  std::vector<std::string> additional_sources;
  TagsFilter filter;
  bool offline_only = false;
  bool continue_on_error = false;
  bool operator==(const GetAvailableWorldsRequest&) const = default;
};
struct GetAvailableWorldsResponse {
  static constexpr std::string_view kService = GetAvailableWorldsRequest::kService;
  static constexpr std::uint8_t kDefaultSourcesFailed = 101;
  Result result;
  std::vector<WorldResource> worlds;
  bool operator==(const GetAvailableWorldsResponse&) const = default;
};

// ---------------------------------------------------------------------------------------------
// The SimulateSteps action: its goal request, result response and feedback message (the halves
// every action shares are rbsim/interfaces.hpp's SendGoalResponse and GetResultRequest, its cancel
// action_msgs' CancelGoal).
struct SimulateStepsSendGoalRequest {
  static constexpr std::string_view kAction = "simulation_interfaces/action/SimulateSteps";
  static constexpr std::string_view kService = "simulation_interfaces/action/SimulateSteps_SendGoal";
  GoalUuid goal_id{};
  std::uint64_t steps = 0;
  bool operator==(const SimulateStepsSendGoalRequest&) const = default;
};
struct SimulateStepsGetResultResponse {
  static constexpr std::string_view kService = "simulation_interfaces/action/SimulateSteps_GetResult";
  std::int8_t status = GoalStatus::kUnknown;
  Result result;
  bool operator==(const SimulateStepsGetResultResponse&) const = default;
};
struct SimulateStepsFeedbackMessage {
  static constexpr std::string_view kType = "simulation_interfaces/action/SimulateSteps_FeedbackMessage";
  GoalUuid goal_id{};
  std::uint64_t completed_steps = 0;
  std::uint64_t remaining_steps = 0;
  bool operator==(const SimulateStepsFeedbackMessage&) const = default;
};

// ---------------------------------------------------------------------------------------------
// Codecs (found by argument-dependent lookup beside rbsim/interfaces.hpp's): encode() replaces
// `out` with the message's CDR; decode() fills `out` (replaced whole) or fails naming the type and
// the offset.

#define RBSIM_SIMULATION_CODEC(T)            \
  void encode(const T& message, Bytes& out); \
  [[nodiscard]] Status decode(std::span<const std::byte> cdr, T& out);
RBSIM_SIMULATION_CODEC(SimulatorFeatures)
RBSIM_SIMULATION_CODEC(Bounds)
RBSIM_SIMULATION_CODEC(EntityFilters)
RBSIM_SIMULATION_CODEC(EntityState)
RBSIM_SIMULATION_CODEC(PoseStamped)
RBSIM_SIMULATION_CODEC(Resource)
RBSIM_SIMULATION_CODEC(WorldResource)
RBSIM_SIMULATION_CODEC(Spawnable)
RBSIM_SIMULATION_CODEC(SpawnEntity)
RBSIM_SIMULATION_CODEC(SpawnResult)
RBSIM_SIMULATION_CODEC(GetSimulatorFeaturesRequest)
RBSIM_SIMULATION_CODEC(GetSimulatorFeaturesResponse)
RBSIM_SIMULATION_CODEC(GetSimulationStateRequest)
RBSIM_SIMULATION_CODEC(GetSimulationStateResponse)
RBSIM_SIMULATION_CODEC(SetSimulationStateRequest)
RBSIM_SIMULATION_CODEC(SetSimulationStateResponse)
RBSIM_SIMULATION_CODEC(ResetSimulationRequest)
RBSIM_SIMULATION_CODEC(ResetSimulationResponse)
RBSIM_SIMULATION_CODEC(StepSimulationRequest)
RBSIM_SIMULATION_CODEC(StepSimulationResponse)
RBSIM_SIMULATION_CODEC(GetEntitiesRequest)
RBSIM_SIMULATION_CODEC(GetEntitiesResponse)
RBSIM_SIMULATION_CODEC(GetEntitiesStatesRequest)
RBSIM_SIMULATION_CODEC(GetEntitiesStatesResponse)
RBSIM_SIMULATION_CODEC(GetEntityInfoRequest)
RBSIM_SIMULATION_CODEC(GetEntityInfoResponse)
RBSIM_SIMULATION_CODEC(GetEntityStateRequest)
RBSIM_SIMULATION_CODEC(GetEntityStateResponse)
RBSIM_SIMULATION_CODEC(SetEntityStateRequest)
RBSIM_SIMULATION_CODEC(SetEntityStateResponse)
RBSIM_SIMULATION_CODEC(GetEntityBoundsRequest)
RBSIM_SIMULATION_CODEC(GetEntityBoundsResponse)
RBSIM_SIMULATION_CODEC(SpawnEntityRequest)
RBSIM_SIMULATION_CODEC(SpawnEntityResponse)
RBSIM_SIMULATION_CODEC(SpawnEntitiesRequest)
RBSIM_SIMULATION_CODEC(SpawnEntitiesResponse)
RBSIM_SIMULATION_CODEC(DeleteEntityRequest)
RBSIM_SIMULATION_CODEC(DeleteEntityResponse)
RBSIM_SIMULATION_CODEC(GetSpawnablesRequest)
RBSIM_SIMULATION_CODEC(GetSpawnablesResponse)
RBSIM_SIMULATION_CODEC(LoadWorldRequest)
RBSIM_SIMULATION_CODEC(LoadWorldResponse)
RBSIM_SIMULATION_CODEC(UnloadWorldRequest)
RBSIM_SIMULATION_CODEC(UnloadWorldResponse)
RBSIM_SIMULATION_CODEC(GetCurrentWorldRequest)
RBSIM_SIMULATION_CODEC(GetCurrentWorldResponse)
RBSIM_SIMULATION_CODEC(GetAvailableWorldsRequest)
RBSIM_SIMULATION_CODEC(GetAvailableWorldsResponse)
RBSIM_SIMULATION_CODEC(SimulateStepsSendGoalRequest)
RBSIM_SIMULATION_CODEC(SimulateStepsGetResultResponse)
RBSIM_SIMULATION_CODEC(SimulateStepsFeedbackMessage)
#undef RBSIM_SIMULATION_CODEC

}  // namespace rbsim::msgs::simulation
