// The service and parameter interfaces the interfaces fuzz target decodes, in the order of the
// type byte that starts each input (shared by the target and the seed writer): rbsim/interfaces.hpp's,
// then simulation_interfaces' (rbsim/simulation_interfaces.hpp). New types go at the end, so the
// byte of every kept input still names its type.
#pragma once

#include <cstddef>
#include <tuple>
#include <type_traits>
#include <utility>

#include "rbsim/interfaces.hpp"
#include "rbsim/simulation_interfaces.hpp"

namespace rbsim::fuzz {

namespace m = rbsim::msgs;
namespace sim = rbsim::msgs::simulation;
using InterfaceTypes = std::tuple<
    m::ParameterValue, m::Parameter, m::ParameterDescriptor, m::SetParametersResult, m::ListParametersResult,
    m::ParameterEvent, m::ListParametersRequest, m::ListParametersResponse, m::GetParametersRequest,
    m::GetParametersResponse, m::SetParametersRequest, m::SetParametersResponse,
    m::SetParametersAtomicallyRequest, m::SetParametersAtomicallyResponse, m::DescribeParametersRequest,
    m::DescribeParametersResponse, m::GetParameterTypesRequest, m::GetParameterTypesResponse,
    m::TriggerRequest, m::TriggerResponse, m::StepRequest, m::StepResponse, m::ApplyImpulseRequest,
    m::ApplyImpulseResponse, m::PauseRequest, m::PauseResponse, m::ResumeRequest, m::ResumeResponse,
    m::TogglePausedRequest, m::TogglePausedResponse, m::IsPausedRequest, m::IsPausedResponse,
    m::GetRateRequest, m::GetRateResponse, m::SetRateRequest, m::SetRateResponse, m::SeekRequest,
    m::SeekResponse, m::PlayNextRequest, m::PlayNextResponse, m::BurstRequest, m::BurstResponse,
    sim::SimulatorFeatures, sim::Bounds, sim::EntityFilters, sim::EntityState,
    sim::GetSimulatorFeaturesRequest, sim::GetSimulatorFeaturesResponse, sim::GetSimulationStateRequest,
    sim::GetSimulationStateResponse, sim::SetSimulationStateRequest, sim::SetSimulationStateResponse,
    sim::ResetSimulationRequest, sim::ResetSimulationResponse, sim::StepSimulationRequest,
    sim::StepSimulationResponse, sim::GetEntitiesRequest, sim::GetEntitiesResponse,
    sim::GetEntitiesStatesRequest, sim::GetEntitiesStatesResponse, sim::GetEntityInfoRequest,
    sim::GetEntityInfoResponse, sim::GetEntityStateRequest, sim::GetEntityStateResponse,
    sim::SetEntityStateRequest, sim::SetEntityStateResponse, sim::GetEntityBoundsRequest,
    sim::GetEntityBoundsResponse, sim::SimulateStepsSendGoalRequest, sim::SimulateStepsGetResultResponse,
    sim::SimulateStepsFeedbackMessage, sim::PoseStamped, sim::Resource, sim::WorldResource, sim::Spawnable,
    sim::SpawnEntity, sim::SpawnResult, sim::SpawnEntityRequest, sim::SpawnEntityResponse,
    sim::SpawnEntitiesRequest, sim::SpawnEntitiesResponse, sim::DeleteEntityRequest,
    sim::DeleteEntityResponse, sim::GetSpawnablesRequest, sim::GetSpawnablesResponse, sim::LoadWorldRequest,
    sim::LoadWorldResponse, sim::UnloadWorldRequest, sim::UnloadWorldResponse, sim::GetCurrentWorldRequest,
    sim::GetCurrentWorldResponse, sim::GetAvailableWorldsRequest, sim::GetAvailableWorldsResponse>;
inline constexpr std::size_t kInterfaceCount = std::tuple_size_v<InterfaceTypes>;
static_assert(kInterfaceCount <= 256, "the type is one input byte");

// The index of T in InterfaceTypes (its input byte).
template <class T>
constexpr std::size_t interface_index() {
  return []<std::size_t... I>(std::index_sequence<I...>) {
    std::size_t at = 0;
    ((std::is_same_v<T, std::tuple_element_t<I, InterfaceTypes>> ? (at = I, 0) : 0), ...);
    return at;
  }
  (std::make_index_sequence<kInterfaceCount>{});
}

// Calls f.template operator()<T>() with T the type of index i (< kInterfaceCount).
template <class F>
void with_interface(std::size_t i, F&& f) {
  [&]<std::size_t... I>(std::index_sequence<I...>) {
    ((I == i ? (f.template operator()<std::tuple_element_t<I, InterfaceTypes>>(), 0) : 0), ...);
  }
  (std::make_index_sequence<kInterfaceCount>{});
}

}  // namespace rbsim::fuzz
