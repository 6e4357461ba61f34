// CDR codecs of simulation_interfaces (rbsim/simulation_interfaces.hpp), on the one writer and the
// one cursor, through the codec skeleton interfaces.cpp uses (interface_codec.hpp).
#include "rbsim/simulation_interfaces.hpp"

#include "interface_codec.hpp"

namespace rbsim::msgs::simulation {

using detail::CdrWriter;
using detail::get_strings;
using detail::kMinString;
using detail::put_strings;
using detail::Reader;

namespace {

// The fewest bytes an element of a sequence takes (see interface_codec.hpp's kMinString).
constexpr std::size_t kMinVector3 = 3 * 8;
// header (time, frame), pose (3 + 4 doubles)
constexpr std::size_t kMinPoseStamped = 8 + kMinString + 7 * 8;
// header and pose, twist, accel (6 doubles each)
constexpr std::size_t kMinEntityState = kMinPoseStamped + 2 * 6 * 8;
constexpr std::size_t kMinResource = 2 * kMinString;
// name, allow_renaming, entity_resource, entity_namespace, initial_pose
constexpr std::size_t kMinSpawnEntity = kMinString + 1 + kMinResource + kMinString + kMinPoseStamped;
// result (code, error_message), entity_name
constexpr std::size_t kMinSpawnResult = 1 + 2 * kMinString;
// entity_resource, description, spawn_bounds (type, the points' length)
constexpr std::size_t kMinSpawnable = kMinResource + kMinString + 1 + 4;
// name, world_resource, description, the tags' length
constexpr std::size_t kMinWorldResource = kMinString + kMinResource + kMinString + 4;

void put(CdrWriter& w, const Result& m) {
  w.u8(m.result);
  w.string(m.error_message);
}
void get(Reader& r, Result& m) {
  m.result = r.get<std::uint8_t>();
  m.error_message = r.string();
}
void put(CdrWriter& w, const Vector3& m) {
  w.f64(m.x);
  w.f64(m.y);
  w.f64(m.z);
}
void get(Reader& r, Vector3& m) {
  m.x = r.get<double>();
  m.y = r.get<double>();
  m.z = r.get<double>();
}
void put(CdrWriter& w, const SimulatorFeatures& m) {
  w.sequence_length(m.features.size());
  for (const std::uint16_t f : m.features) w.u16(f);
  put_strings(w, m.spawn_formats);
  w.string(m.custom_info);
}
void get(Reader& r, SimulatorFeatures& m) {
  m.features.resize(r.length(2));
  for (std::uint16_t& f : m.features) f = r.get<std::uint16_t>();
  get_strings(r, m.spawn_formats);
  m.custom_info = r.string();
}
void put(CdrWriter& w, const Bounds& m) {
  w.u8(m.type);
  w.sequence_length(m.points.size());
  for (const Vector3& p : m.points) put(w, p);
}
void get(Reader& r, Bounds& m) {
  m.type = r.get<std::uint8_t>();
  m.points.resize(r.length(kMinVector3));
  for (Vector3& p : m.points) get(r, p);
}
void put(CdrWriter& w, const TagsFilter& m) {
  put_strings(w, m.tags);
  w.u8(m.filter_mode);
}
void get(Reader& r, TagsFilter& m) {
  get_strings(r, m.tags);
  m.filter_mode = r.get<std::uint8_t>();
}
void put(CdrWriter& w, const EntityFilters& m) {
  w.string(m.filter);
  w.sequence_length(m.categories.size());
  for (const std::uint8_t c : m.categories) w.u8(c);  // EntityCategory: one uint8 each
  put(w, m.tags);
  put(w, m.bounds);
}
void get(Reader& r, EntityFilters& m) {
  m.filter = r.string();
  m.categories.resize(r.length(1));
  for (std::uint8_t& c : m.categories) c = r.get<std::uint8_t>();
  get(r, m.tags);
  get(r, m.bounds);
}
void put(CdrWriter& w, const EntityInfo& m) {
  w.u8(m.category);
  w.string(m.description);
  put_strings(w, m.tags);
}
void get(Reader& r, EntityInfo& m) {
  m.category = r.get<std::uint8_t>();
  m.description = r.string();
  get_strings(r, m.tags);
}
void put(CdrWriter& w, const Quaternion& m) {
  w.f64(m.x);
  w.f64(m.y);
  w.f64(m.z);
  w.f64(m.w);
}
void get(Reader& r, Quaternion& m) {
  m.x = r.get<double>();
  m.y = r.get<double>();
  m.z = r.get<double>();
  m.w = r.get<double>();
}
void put(CdrWriter& w, const EntityState& m) {
  w.header(m.stamp, m.frame_id);
  put(w, m.position);
  put(w, m.orientation);
  put(w, m.linear_velocity);
  put(w, m.angular_velocity);
  put(w, m.linear_acceleration);
  put(w, m.angular_acceleration);
}
void get(Reader& r, EntityState& m) {
  m.stamp = r.time();
  m.frame_id = r.string();
  get(r, m.position);
  get(r, m.orientation);
  get(r, m.linear_velocity);
  get(r, m.angular_velocity);
  get(r, m.linear_acceleration);
  get(r, m.angular_acceleration);
}
void put(CdrWriter& w, const PoseStamped& m) {
  w.header(m.stamp, m.frame_id);
  put(w, m.position);
  put(w, m.orientation);
}
void get(Reader& r, PoseStamped& m) {
  m.stamp = r.time();
  m.frame_id = r.string();
  get(r, m.position);
  get(r, m.orientation);
}
void put(CdrWriter& w, const Resource& m) {
  w.string(m.uri);
  w.string(m.resource_string);
}
void get(Reader& r, Resource& m) {
  m.uri = r.string();
  m.resource_string = r.string();
}
void put(CdrWriter& w, const WorldResource& m) {
  w.string(m.name);
  put(w, m.world_resource);
  w.string(m.description);
  put_strings(w, m.tags);
}
void get(Reader& r, WorldResource& m) {
  m.name = r.string();
  get(r, m.world_resource);
  m.description = r.string();
  get_strings(r, m.tags);
}
void put(CdrWriter& w, const Spawnable& m) {
  put(w, m.entity_resource);
  w.string(m.description);
  put(w, m.spawn_bounds);
}
void get(Reader& r, Spawnable& m) {
  get(r, m.entity_resource);
  m.description = r.string();
  get(r, m.spawn_bounds);
}
// SpawnEntity.msg has the fields of SpawnEntity.srv's request, SpawnResult.msg those of its
// response: one writer and one reader of each pair.
template <class T>  // SpawnEntity, SpawnEntityRequest
void put_spawn_entity(CdrWriter& w, const T& m) {
  w.string(m.name);
  w.boolean(m.allow_renaming);
  put(w, m.entity_resource);
  w.string(m.entity_namespace);
  put(w, m.initial_pose);
}
template <class T>
void get_spawn_entity(Reader& r, T& m) {
  m.name = r.string();
  m.allow_renaming = r.get<std::uint8_t>() != 0;
  get(r, m.entity_resource);
  m.entity_namespace = r.string();
  get(r, m.initial_pose);
}
template <class T>  // SpawnResult, SpawnEntityResponse
void put_spawn_result(CdrWriter& w, const T& m) {
  put(w, m.result);
  w.string(m.entity_name);
}
template <class T>
void get_spawn_result(Reader& r, T& m) {
  get(r, m.result);
  m.entity_name = r.string();
}
void put(CdrWriter& w, const SpawnEntity& m) {
  put_spawn_entity(w, m);
}
void get(Reader& r, SpawnEntity& m) {
  get_spawn_entity(r, m);
}
void put(CdrWriter& w, const SpawnResult& m) {
  put_spawn_result(w, m);
}
void get(Reader& r, SpawnResult& m) {
  get_spawn_result(r, m);
}
// An empty request or response has one member on the wire, `uint8 structure_needs_at_least_one_member`
// (written 0, read and ignored).
void put(CdrWriter& w, const GetSimulatorFeaturesRequest&) {
  w.u8(0);
}
void get(Reader& r, GetSimulatorFeaturesRequest&) {
  (void)r.get<std::uint8_t>();
}
void put(CdrWriter& w, const GetSimulatorFeaturesResponse& m) {
  put(w, m.features);
}
void get(Reader& r, GetSimulatorFeaturesResponse& m) {
  get(r, m.features);
}
void put(CdrWriter& w, const GetSimulationStateRequest&) {
  w.u8(0);
}
void get(Reader& r, GetSimulationStateRequest&) {
  (void)r.get<std::uint8_t>();
}
void put(CdrWriter& w, const GetSimulationStateResponse& m) {
  w.u8(m.state);
  put(w, m.result);
}
void get(Reader& r, GetSimulationStateResponse& m) {
  m.state = r.get<std::uint8_t>();
  get(r, m.result);
}
void put(CdrWriter& w, const SetSimulationStateRequest& m) {
  w.u8(m.state);
}
void get(Reader& r, SetSimulationStateRequest& m) {
  m.state = r.get<std::uint8_t>();
}
void put(CdrWriter& w, const SetSimulationStateResponse& m) {
  put(w, m.result);
}
void get(Reader& r, SetSimulationStateResponse& m) {
  get(r, m.result);
}
void put(CdrWriter& w, const ResetSimulationRequest& m) {
  w.u8(m.scope);
}
void get(Reader& r, ResetSimulationRequest& m) {
  m.scope = r.get<std::uint8_t>();
}
void put(CdrWriter& w, const ResetSimulationResponse& m) {
  put(w, m.result);
}
void get(Reader& r, ResetSimulationResponse& m) {
  get(r, m.result);
}
void put(CdrWriter& w, const StepSimulationRequest& m) {
  w.u64(m.steps);
}
void get(Reader& r, StepSimulationRequest& m) {
  m.steps = r.get<std::uint64_t>();
}
void put(CdrWriter& w, const StepSimulationResponse& m) {
  put(w, m.result);
}
void get(Reader& r, StepSimulationResponse& m) {
  get(r, m.result);
}
void put(CdrWriter& w, const GetEntitiesRequest& m) {
  put(w, m.filters);
}
void get(Reader& r, GetEntitiesRequest& m) {
  get(r, m.filters);
}
void put(CdrWriter& w, const GetEntitiesResponse& m) {
  put(w, m.result);
  put_strings(w, m.entities);
}
void get(Reader& r, GetEntitiesResponse& m) {
  get(r, m.result);
  get_strings(r, m.entities);
}
void put(CdrWriter& w, const GetEntitiesStatesRequest& m) {
  put(w, m.filters);
}
void get(Reader& r, GetEntitiesStatesRequest& m) {
  get(r, m.filters);
}
void put(CdrWriter& w, const GetEntitiesStatesResponse& m) {
  put(w, m.result);
  put_strings(w, m.entities);
  w.sequence_length(m.states.size());
  for (const EntityState& s : m.states) put(w, s);
}
void get(Reader& r, GetEntitiesStatesResponse& m) {
  get(r, m.result);
  get_strings(r, m.entities);
  m.states.resize(r.length(kMinEntityState));
  for (EntityState& s : m.states) get(r, s);
}
void put(CdrWriter& w, const GetEntityInfoRequest& m) {
  w.string(m.entity);
}
void get(Reader& r, GetEntityInfoRequest& m) {
  m.entity = r.string();
}
void put(CdrWriter& w, const GetEntityInfoResponse& m) {
  put(w, m.result);
  put(w, m.info);
}
void get(Reader& r, GetEntityInfoResponse& m) {
  get(r, m.result);
  get(r, m.info);
}
void put(CdrWriter& w, const GetEntityStateRequest& m) {
  w.string(m.entity);
}
void get(Reader& r, GetEntityStateRequest& m) {
  m.entity = r.string();
}
void put(CdrWriter& w, const GetEntityStateResponse& m) {
  put(w, m.result);
  put(w, m.state);
}
void get(Reader& r, GetEntityStateResponse& m) {
  get(r, m.result);
  get(r, m.state);
}
void put(CdrWriter& w, const SetEntityStateRequest& m) {
  w.string(m.entity);
  put(w, m.state);
  w.boolean(m.set_pose);
  w.boolean(m.set_twist);
  w.boolean(m.set_acceleration);
}
void get(Reader& r, SetEntityStateRequest& m) {
  m.entity = r.string();
  get(r, m.state);
  m.set_pose = r.get<std::uint8_t>() != 0;
  m.set_twist = r.get<std::uint8_t>() != 0;
  m.set_acceleration = r.get<std::uint8_t>() != 0;
}
void put(CdrWriter& w, const SetEntityStateResponse& m) {
  put(w, m.result);
}
void get(Reader& r, SetEntityStateResponse& m) {
  get(r, m.result);
}
void put(CdrWriter& w, const GetEntityBoundsRequest& m) {
  w.string(m.entity);
}
void get(Reader& r, GetEntityBoundsRequest& m) {
  m.entity = r.string();
}
void put(CdrWriter& w, const GetEntityBoundsResponse& m) {
  put(w, m.result);
  put(w, m.bounds);
}
void get(Reader& r, GetEntityBoundsResponse& m) {
  get(r, m.result);
  get(r, m.bounds);
}
void put(CdrWriter& w, const SpawnEntityRequest& m) {
  put_spawn_entity(w, m);
}
void get(Reader& r, SpawnEntityRequest& m) {
  get_spawn_entity(r, m);
}
void put(CdrWriter& w, const SpawnEntityResponse& m) {
  put_spawn_result(w, m);
}
void get(Reader& r, SpawnEntityResponse& m) {
  get_spawn_result(r, m);
}
void put(CdrWriter& w, const SpawnEntitiesRequest& m) {
  w.sequence_length(m.spawn_requests.size());
  for (const SpawnEntity& e : m.spawn_requests) put(w, e);
}
void get(Reader& r, SpawnEntitiesRequest& m) {
  m.spawn_requests.resize(r.length(kMinSpawnEntity));
  for (SpawnEntity& e : m.spawn_requests) get(r, e);
}
void put(CdrWriter& w, const SpawnEntitiesResponse& m) {
  put(w, m.result);
  w.sequence_length(m.results.size());
  for (const SpawnResult& s : m.results) put(w, s);
}
void get(Reader& r, SpawnEntitiesResponse& m) {
  get(r, m.result);
  m.results.resize(r.length(kMinSpawnResult));
  for (SpawnResult& s : m.results) get(r, s);
}
void put(CdrWriter& w, const DeleteEntityRequest& m) {
  w.string(m.entity);
}
void get(Reader& r, DeleteEntityRequest& m) {
  m.entity = r.string();
}
void put(CdrWriter& w, const DeleteEntityResponse& m) {
  put(w, m.result);
}
void get(Reader& r, DeleteEntityResponse& m) {
  get(r, m.result);
}
void put(CdrWriter& w, const GetSpawnablesRequest& m) {
  put_strings(w, m.sources);
}
void get(Reader& r, GetSpawnablesRequest& m) {
  get_strings(r, m.sources);
}
void put(CdrWriter& w, const GetSpawnablesResponse& m) {
  put(w, m.result);
  w.sequence_length(m.spawnables.size());
  for (const Spawnable& s : m.spawnables) put(w, s);
}
void get(Reader& r, GetSpawnablesResponse& m) {
  get(r, m.result);
  m.spawnables.resize(r.length(kMinSpawnable));
  for (Spawnable& s : m.spawnables) get(r, s);
}
void put(CdrWriter& w, const LoadWorldRequest& m) {
  put(w, m.world_resource);
  w.boolean(m.fail_on_unsupported_element);
  w.boolean(m.ignore_missing_or_unsupported_assets);
}
void get(Reader& r, LoadWorldRequest& m) {
  get(r, m.world_resource);
  m.fail_on_unsupported_element = r.get<std::uint8_t>() != 0;
  m.ignore_missing_or_unsupported_assets = r.get<std::uint8_t>() != 0;
}
void put(CdrWriter& w, const LoadWorldResponse& m) {
  put(w, m.result);
  put(w, m.world);
}
void get(Reader& r, LoadWorldResponse& m) {
  get(r, m.result);
  get(r, m.world);
}
void put(CdrWriter& w, const UnloadWorldRequest&) {
  w.u8(0);
}
void get(Reader& r, UnloadWorldRequest&) {
  (void)r.get<std::uint8_t>();
}
void put(CdrWriter& w, const UnloadWorldResponse& m) {
  put(w, m.result);
}
void get(Reader& r, UnloadWorldResponse& m) {
  get(r, m.result);
}
void put(CdrWriter& w, const GetCurrentWorldRequest&) {
  w.u8(0);
}
void get(Reader& r, GetCurrentWorldRequest&) {
  (void)r.get<std::uint8_t>();
}
void put(CdrWriter& w, const GetCurrentWorldResponse& m) {
  put(w, m.result);
  put(w, m.world);
}
void get(Reader& r, GetCurrentWorldResponse& m) {
  get(r, m.result);
  get(r, m.world);
}
void put(CdrWriter& w, const GetAvailableWorldsRequest& m) {
  put_strings(w, m.additional_sources);
  put(w, m.filter);
  w.boolean(m.offline_only);
  w.boolean(m.continue_on_error);
}
void get(Reader& r, GetAvailableWorldsRequest& m) {
  get_strings(r, m.additional_sources);
  get(r, m.filter);
  m.offline_only = r.get<std::uint8_t>() != 0;
  m.continue_on_error = r.get<std::uint8_t>() != 0;
}
void put(CdrWriter& w, const GetAvailableWorldsResponse& m) {
  put(w, m.result);
  w.sequence_length(m.worlds.size());
  for (const WorldResource& world : m.worlds) put(w, world);
}
void get(Reader& r, GetAvailableWorldsResponse& m) {
  get(r, m.result);
  m.worlds.resize(r.length(kMinWorldResource));
  for (WorldResource& world : m.worlds) get(r, world);
}

void put(CdrWriter& w, const SimulateStepsSendGoalRequest& m) {
  detail::put_uuid(w, m.goal_id);
  w.u64(m.steps);
}
void get(Reader& r, SimulateStepsSendGoalRequest& m) {
  detail::get_uuid(r, m.goal_id);
  m.steps = r.get<std::uint64_t>();
}
void put(CdrWriter& w, const SimulateStepsGetResultResponse& m) {
  w.u8(static_cast<std::uint8_t>(m.status));
  put(w, m.result);
}
void get(Reader& r, SimulateStepsGetResultResponse& m) {
  m.status = r.get<std::int8_t>();
  get(r, m.result);
}
void put(CdrWriter& w, const SimulateStepsFeedbackMessage& m) {
  detail::put_uuid(w, m.goal_id);
  w.u64(m.completed_steps);
  w.u64(m.remaining_steps);
}
void get(Reader& r, SimulateStepsFeedbackMessage& m) {
  detail::get_uuid(r, m.goal_id);
  m.completed_steps = r.get<std::uint64_t>();
  m.remaining_steps = r.get<std::uint64_t>();
}

}  // namespace

RBSIM_DEFINE_CODEC(SimulatorFeatures, "")
RBSIM_DEFINE_CODEC(Bounds, "")
RBSIM_DEFINE_CODEC(EntityFilters, "")
RBSIM_DEFINE_CODEC(EntityState, "")
RBSIM_DEFINE_CODEC(PoseStamped, "")
RBSIM_DEFINE_CODEC(Resource, "")
RBSIM_DEFINE_CODEC(WorldResource, "")
RBSIM_DEFINE_CODEC(Spawnable, "")
RBSIM_DEFINE_CODEC(SpawnEntity, "")
RBSIM_DEFINE_CODEC(SpawnResult, "")
RBSIM_DEFINE_CODEC(GetSimulatorFeaturesRequest, " request")
RBSIM_DEFINE_CODEC(GetSimulatorFeaturesResponse, " response")
RBSIM_DEFINE_CODEC(GetSimulationStateRequest, " request")
RBSIM_DEFINE_CODEC(GetSimulationStateResponse, " response")
RBSIM_DEFINE_CODEC(SetSimulationStateRequest, " request")
RBSIM_DEFINE_CODEC(SetSimulationStateResponse, " response")
RBSIM_DEFINE_CODEC(ResetSimulationRequest, " request")
RBSIM_DEFINE_CODEC(ResetSimulationResponse, " response")
RBSIM_DEFINE_CODEC(StepSimulationRequest, " request")
RBSIM_DEFINE_CODEC(StepSimulationResponse, " response")
RBSIM_DEFINE_CODEC(GetEntitiesRequest, " request")
RBSIM_DEFINE_CODEC(GetEntitiesResponse, " response")
RBSIM_DEFINE_CODEC(GetEntitiesStatesRequest, " request")
RBSIM_DEFINE_CODEC(GetEntitiesStatesResponse, " response")
RBSIM_DEFINE_CODEC(GetEntityInfoRequest, " request")
RBSIM_DEFINE_CODEC(GetEntityInfoResponse, " response")
RBSIM_DEFINE_CODEC(GetEntityStateRequest, " request")
RBSIM_DEFINE_CODEC(GetEntityStateResponse, " response")
RBSIM_DEFINE_CODEC(SetEntityStateRequest, " request")
RBSIM_DEFINE_CODEC(SetEntityStateResponse, " response")
RBSIM_DEFINE_CODEC(GetEntityBoundsRequest, " request")
RBSIM_DEFINE_CODEC(GetEntityBoundsResponse, " response")
RBSIM_DEFINE_CODEC(SpawnEntityRequest, " request")
RBSIM_DEFINE_CODEC(SpawnEntityResponse, " response")
RBSIM_DEFINE_CODEC(SpawnEntitiesRequest, " request")
RBSIM_DEFINE_CODEC(SpawnEntitiesResponse, " response")
RBSIM_DEFINE_CODEC(DeleteEntityRequest, " request")
RBSIM_DEFINE_CODEC(DeleteEntityResponse, " response")
RBSIM_DEFINE_CODEC(GetSpawnablesRequest, " request")
RBSIM_DEFINE_CODEC(GetSpawnablesResponse, " response")
RBSIM_DEFINE_CODEC(LoadWorldRequest, " request")
RBSIM_DEFINE_CODEC(LoadWorldResponse, " response")
RBSIM_DEFINE_CODEC(UnloadWorldRequest, " request")
RBSIM_DEFINE_CODEC(UnloadWorldResponse, " response")
RBSIM_DEFINE_CODEC(GetCurrentWorldRequest, " request")
RBSIM_DEFINE_CODEC(GetCurrentWorldResponse, " response")
RBSIM_DEFINE_CODEC(GetAvailableWorldsRequest, " request")
RBSIM_DEFINE_CODEC(GetAvailableWorldsResponse, " response")
RBSIM_DEFINE_CODEC(SimulateStepsSendGoalRequest, " request")
RBSIM_DEFINE_CODEC(SimulateStepsGetResultResponse, " response")
RBSIM_DEFINE_CODEC(SimulateStepsFeedbackMessage, "")

}  // namespace rbsim::msgs::simulation
