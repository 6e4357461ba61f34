// simulation_interfaces' spawning, deleting and world types, each filled (every field set apart
// from its zero, two bools side by side unequal so a swap would show), with the name rosidl gives
// its message: shared by the codec tests and the from_json tests.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "rbsim/simulation_interfaces.hpp"

namespace rbsim::msgs::simulation {

inline PoseStamped some_pose() {
  return {{7, 250}, "map", {1.5, -2.0, 0.25}, quaternion_z(0.5)};
}
inline Resource some_resource() {
  return {"file:///models/cart.sdf", "<sdf version='1.9'><model name='cart'/></sdf>"};
}
inline WorldResource some_world() {
  return {
      "warehouse", {"package://worlds/warehouse.sdf", "<world/>"}, "a small warehouse", {"indoor", "small"}};
}
inline Spawnable some_spawnable() {
  return {some_resource(),
          "cart with a lidar",
          {static_cast<std::uint8_t>(BoundsType::Box), {{1.0, 1.0, 0.5}, {-1.0, -1.0, 0.0}}}};
}
inline SpawnEntity some_spawn() {
  return {"cart_1", true, some_resource(), "/fleet", some_pose()};
}
inline SpawnResult some_spawn_result() {
  return {{SpawnResult::kNameNotUnique, "cart_1 is taken"}, "cart_1_2"};
}

// Calls f(value, half) for each: half "" for a message (named kType), else "_Request" or
// "_Response" (named kService + half).
template <class F>
void for_each_spawn_and_world_type(F&& f) {
  f(some_pose(), "");
  f(some_resource(), "");
  f(some_world(), "");
  f(some_spawnable(), "");
  f(some_spawn(), "");
  f(some_spawn_result(), "");
  const SpawnEntity e = some_spawn();
  f(SpawnEntityRequest{e.name, e.allow_renaming, e.entity_resource, e.entity_namespace, e.initial_pose},
    "_Request");
  f(SpawnEntityResponse{{SpawnEntityResponse::kInvalidPose, "not a unit quaternion"}, "cart_9"}, "_Response");
  f(SpawnEntitiesRequest{{e, SpawnEntity{}, {"", false, {"", "<urdf/>"}, "", {}}}}, "_Request");
  f(SpawnEntitiesResponse{{SpawnEntitiesResponse::kEntitiesSpawnFailed, "1 of 2 failed"},
                          {some_spawn_result(), {{Result::kOk, ""}, "cart_2"}}},
    "_Response");
  f(DeleteEntityRequest{"cart_1"}, "_Request");
  f(DeleteEntityResponse{{Result::kNotFound, "no cart_1"}}, "_Response");
  f(GetSpawnablesRequest{{"file:///opt/models", "fuel://"}}, "_Request");
  f(GetSpawnablesResponse{{Result::kOk, "fuel:// unknown"}, {some_spawnable(), Spawnable{}}}, "_Response");
  f(LoadWorldRequest{{"", "<sdf/>"}, false, true}, "_Request");
  f(LoadWorldResponse{{LoadWorldResponse::kMissingAssets, "mesh.dae"}, some_world()}, "_Response");
  f(UnloadWorldRequest{}, "_Request");
  f(UnloadWorldResponse{{UnloadWorldResponse::kNoWorldLoaded, "no world"}}, "_Response");
  f(GetCurrentWorldRequest{}, "_Request");
  f(GetCurrentWorldResponse{{Result::kOk, ""}, some_world()}, "_Response");
  f(
      GetAvailableWorldsRequest{
          {"https://fuel.example/worlds"}, {{"indoor", "small"}, TagsFilter::kFilterModeAll}, true, false},
      "_Request");
  f(GetAvailableWorldsResponse{{GetAvailableWorldsResponse::kDefaultSourcesFailed, "offline"},
                               {some_world(), WorldResource{}}},
    "_Response");
}

template <class T>
std::string rosidl_name(std::string_view half) {
  if constexpr (requires { T::kType; }) {
    return std::string(T::kType);
  } else {
    return std::string(T::kService) + std::string(half);
  }
}

}  // namespace rbsim::msgs::simulation
