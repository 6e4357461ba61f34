// The service and parameter interfaces the interfaces fuzz target decodes, in the order of the
// type byte that starts each input (shared by the target and the seed writer).
#pragma once

#include <cstddef>
#include <tuple>
#include <utility>

#include "rbsim/interfaces.hpp"

namespace rbsim::fuzz {

namespace m = rbsim::msgs;
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
    m::SeekResponse, m::PlayNextRequest, m::PlayNextResponse, m::BurstRequest, m::BurstResponse>;
inline constexpr std::size_t kInterfaceCount = std::tuple_size_v<InterfaceTypes>;

// Calls f.template operator()<T>() with T the type of index i (< kInterfaceCount).
template <class F>
void with_interface(std::size_t i, F&& f) {
  [&]<std::size_t... I>(std::index_sequence<I...>) {
    ((I == i ? (f.template operator()<std::tuple_element_t<I, InterfaceTypes>>(), 0) : 0), ...);
  }
  (std::make_index_sequence<kInterfaceCount>{});
}

}  // namespace rbsim::fuzz
