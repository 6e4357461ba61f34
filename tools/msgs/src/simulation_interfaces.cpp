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
// header (time, frame), pose (3 + 4 doubles), twist, accel (6 doubles each)
constexpr std::size_t kMinEntityState = 8 + kMinString + 7 * 8 + 2 * 6 * 8;

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
void put(CdrWriter& w, const EntityFilters& m) {
  w.string(m.filter);
  w.sequence_length(m.categories.size());
  for (const std::uint8_t c : m.categories) w.u8(c);  // EntityCategory: one uint8 each
  put_strings(w, m.tags.tags);
  w.u8(m.tags.filter_mode);
  put(w, m.bounds);
}
void get(Reader& r, EntityFilters& m) {
  m.filter = r.string();
  m.categories.resize(r.length(1));
  for (std::uint8_t& c : m.categories) c = r.get<std::uint8_t>();
  get_strings(r, m.tags.tags);
  m.tags.filter_mode = r.get<std::uint8_t>();
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
void put(CdrWriter& w, const EntityState& m) {
  w.header(m.stamp, m.frame_id);
  put(w, m.position);
  w.f64(m.orientation.x);
  w.f64(m.orientation.y);
  w.f64(m.orientation.z);
  w.f64(m.orientation.w);
  put(w, m.linear_velocity);
  put(w, m.angular_velocity);
  put(w, m.linear_acceleration);
  put(w, m.angular_acceleration);
}
void get(Reader& r, EntityState& m) {
  m.stamp = r.time();
  m.frame_id = r.string();
  get(r, m.position);
  m.orientation.x = r.get<double>();
  m.orientation.y = r.get<double>();
  m.orientation.z = r.get<double>();
  m.orientation.w = r.get<double>();
  get(r, m.linear_velocity);
  get(r, m.angular_velocity);
  get(r, m.linear_acceleration);
  get(r, m.angular_acceleration);
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
RBSIM_DEFINE_CODEC(SimulateStepsSendGoalRequest, " request")
RBSIM_DEFINE_CODEC(SimulateStepsGetResultResponse, " response")
RBSIM_DEFINE_CODEC(SimulateStepsFeedbackMessage, "")

}  // namespace rbsim::msgs::simulation
