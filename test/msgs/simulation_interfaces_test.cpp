// simulation_interfaces' codecs (rbsim/simulation_interfaces.hpp): every type round-trips through
// its CDR, the bytes follow the definition's field order and alignment, and untrusted bytes
// (truncated, a length past the data, a wrong header) are errors naming the type, never a crash.
#include "rbsim/simulation_interfaces.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <utility>

#include "rbsim/type_hash.hpp"
#include "spawn_world_samples.hpp"

namespace rbsim::msgs::simulation {
namespace {

template <class T>
T round_trip(const T& m) {
  Bytes cdr;
  encode(m, cdr);
  T back;
  const Status st = decode(cdr, back);
  EXPECT_TRUE(st.ok()) << st.error().message;
  return back;
}

EntityState some_state() {
  EntityState s;
  s.stamp = {3, 500000000};
  s.frame_id = "world";
  s.position = {1.0, -2.0, 0.0};
  s.orientation = quaternion_z(0.25);
  s.linear_velocity = {0.5, 0.0, 0.0};
  s.angular_velocity = {0.0, 0.0, 2.0};
  s.linear_acceleration = {0.0, -9.81, 0.0};
  s.angular_acceleration = {0.0, 0.0, -0.5};
  return s;
}

TEST(SimulationInterfacesCodec, EveryTypeRoundTrips) {
  GetEntitiesStatesResponse states;
  states.result = {Result::kOk, ""};
  states.entities = {"body_0", "body_1"};
  states.states = {some_state(), EntityState{}};
  const GetEntitiesStatesResponse back = round_trip(states);
  EXPECT_EQ(back.result, states.result);
  EXPECT_EQ(back.entities, states.entities);
  EXPECT_EQ(back.states, states.states);

  GetEntitiesRequest filters;
  filters.filters.filter = "^body_1$";
  filters.filters.categories = {4};
  filters.filters.tags = {{"a", "b"}, 1};
  filters.filters.bounds = {static_cast<std::uint8_t>(BoundsType::Sphere), {{1, 2, 3}, {0.5, 0, 0}}};
  EXPECT_EQ(round_trip(filters).filters, filters.filters);

  GetSimulatorFeaturesResponse features;
  features.features = {{5, 6, 32}, {"sdf"}, "info"};
  EXPECT_EQ(round_trip(features).features, features.features);

  SetEntityStateRequest set;
  set.entity = "body_3";
  set.state = some_state();
  set.set_twist = true;
  set.set_acceleration = true;
  const SetEntityStateRequest set_back = round_trip(set);
  EXPECT_EQ(set_back.entity, "body_3");
  EXPECT_EQ(set_back.state, set.state);
  EXPECT_FALSE(set_back.set_pose);
  EXPECT_TRUE(set_back.set_twist);
  EXPECT_TRUE(set_back.set_acceleration);

  GetEntityBoundsResponse bounds;
  bounds.result = {Result::kNotFound, "no entity"};
  bounds.bounds = {static_cast<std::uint8_t>(BoundsType::Box), {{1, 1, 0}, {-1, -1, 0}}};
  const GetEntityBoundsResponse bounds_back = round_trip(bounds);
  EXPECT_EQ(bounds_back.result, bounds.result);
  EXPECT_EQ(bounds_back.bounds, bounds.bounds);

  GetEntityInfoResponse info;
  info.result = {Result::kOk, ""};
  info.info = {4, "rigid body", {"t"}};
  EXPECT_EQ(round_trip(info).info, info.info);

  EXPECT_EQ(round_trip(GetSimulationStateResponse{2, {Result::kOk, ""}}).state, 2);
  EXPECT_EQ(round_trip(SetSimulationStateRequest{3}).state, 3);
  EXPECT_EQ(
      round_trip(SetSimulationStateResponse{{SetSimulationStateResponse::kIncorrectTransition, "x"}}).result,
      (Result{103, "x"}));
  EXPECT_EQ(round_trip(ResetSimulationRequest{ResetSimulationRequest::kScopeAll}).scope, 255);
  EXPECT_EQ(round_trip(StepSimulationRequest{7}).steps, 7u);
  EXPECT_EQ(round_trip(GetEntityStateRequest{"body_9"}).entity, "body_9");
}

// The wire layout, byte by byte: header, then `uint64 steps` aligned to 8 from the body's start;
// an empty request is its one placeholder byte; StepSimulation's default is one step.
TEST(SimulationInterfacesCodec, BytesFollowTheDefinition) {
  Bytes cdr;
  encode(StepSimulationRequest{}, cdr);
  ASSERT_EQ(cdr.size(), 12u);
  EXPECT_EQ(cdr[1], std::byte{1});  // CDR_LE
  std::uint64_t steps = 0;
  std::memcpy(&steps, cdr.data() + 4, 8);
  EXPECT_EQ(steps, 1u);

  encode(GetSimulationStateRequest{}, cdr);
  EXPECT_EQ(cdr.size(), 8u);  // header + 1 byte + 3 padding
  EXPECT_EQ(cdr[3], std::byte{3});

  // SimulatorFeatures: u32 count, then u16 values, then the strings.
  SimulatorFeatures f;
  f.features = {5, 300};
  encode(f, cdr);
  std::uint32_t n = 0;
  std::memcpy(&n, cdr.data() + 4, 4);
  EXPECT_EQ(n, 2u);
  std::uint16_t second = 0;
  std::memcpy(&second, cdr.data() + 10, 2);
  EXPECT_EQ(second, 300);
}

TEST(SimulationInterfacesCodec, TruncatedOrHostileBytesAreErrorsNamingTheType) {
  Bytes cdr;
  GetEntitiesStatesResponse states;
  states.entities = {"body_0"};
  states.states = {some_state()};
  encode(states, cdr);
  for (std::size_t n = 0; n < cdr.size() - 4; ++n) {  // the last 4 bytes may be padding only
    GetEntitiesStatesResponse out;
    const Status st = decode(std::span<const std::byte>(cdr.data(), n), out);
    ASSERT_FALSE(st.ok()) << n << " bytes decoded";
    EXPECT_NE(st.error().message.find("simulation_interfaces/srv/GetEntitiesStates response"),
              std::string::npos)
        << st.error().message;
  }
  // A sequence length far past the data fails before anything is allocated.
  Bytes hostile{std::byte{0},    std::byte{1},    std::byte{0},    std::byte{0},
                std::byte{0xff}, std::byte{0xff}, std::byte{0xff}, std::byte{0x7f}};
  SimulatorFeatures f;
  const Status st = decode(hostile, f);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.error().message.find("SimulatorFeatures"), std::string::npos) << st.error().message;
  // A big-endian header is refused.
  Bytes be{std::byte{0}, std::byte{0}, std::byte{0}, std::byte{0},
           std::byte{1}, std::byte{0}, std::byte{0}, std::byte{0}};
  StepSimulationRequest step;
  EXPECT_FALSE(decode(be, step).ok());
}

// ---------------------------------------------------------------------------------------------
// Spawning, deleting and worlds: every type filled (spawn_world_samples.hpp).

TEST(SimulationInterfacesCodec, SpawnAndWorldTypesRoundTripEveryField) {
  std::size_t n = 0;
  for_each_spawn_and_world_type([&]<class T>(const T& m, std::string_view half) {
    SCOPED_TRACE(rosidl_name<T>(half));
    EXPECT_EQ(round_trip(m), m);
    EXPECT_EQ(round_trip(T{}), T{});
    ++n;
  });
  EXPECT_EQ(n, 6u + 8u * 2u);
  // The fields a whole comparison could hide: the bools apart, the pose's every value.
  const LoadWorldRequest load = round_trip(LoadWorldRequest{{"u", "s"}, true, false});
  EXPECT_TRUE(load.fail_on_unsupported_element);
  EXPECT_FALSE(load.ignore_missing_or_unsupported_assets);
  const SpawnEntitiesRequest spawns = round_trip(SpawnEntitiesRequest{{some_spawn()}});
  ASSERT_EQ(spawns.spawn_requests.size(), 1u);
  EXPECT_EQ(spawns.spawn_requests[0].initial_pose.frame_id, "map");
  EXPECT_EQ(spawns.spawn_requests[0].initial_pose.orientation, quaternion_z(0.5));
  EXPECT_TRUE(spawns.spawn_requests[0].allow_renaming);
}

// The names kType and kService are definitions rbsim ships, and each type's REP 2011 hash is the
// one rosbags computes (test/msgs/data/rihs01_rosbags.txt, checked against rosbags itself by
// test/python/check_type_hashes.py); a service's endpoints carry its halves' hashes.
TEST(SimulationInterfacesCodec, SpawnAndWorldTypeHashesMatchRosbags) {
  std::ifstream in(std::filesystem::path(RBSIM_TEST_MSG_DATA) / "rihs01_rosbags.txt");
  ASSERT_TRUE(in) << "test/msgs/data/rihs01_rosbags.txt";
  std::map<std::string, std::string, std::less<>> table;
  for (std::string line; std::getline(in, line);) {
    std::istringstream words(line);
    std::string type, hash;
    if (words >> type >> hash) table[type] = hash;
  }
  const auto expect_hash = [&](const std::string& type) {
    SCOPED_TRACE(type);
    const auto it = table.find(type);
    ASSERT_NE(it, table.end());
    EXPECT_TRUE(it->second.starts_with("RIHS01_"));
    const auto h = type_hash(type);
    ASSERT_TRUE(h.ok()) << h.error().message;
    EXPECT_EQ(h.value(), it->second);
  };
  for_each_spawn_and_world_type([&]<class T>(const T&, std::string_view half) {
    expect_hash(rosidl_name<T>(half));
    if constexpr (requires { T::kService; }) {
      expect_hash(std::string(T::kService));
      expect_hash(std::string(T::kService) + "_Event");
      const auto endpoints = service_endpoint_type_hashes(T::kService);
      ASSERT_TRUE(endpoints.ok());
      EXPECT_EQ(half == "_Request" ? endpoints.value().request : endpoints.value().reply,
                table.find(rosidl_name<T>(half))->second);
    }
  });
  expect_hash("simulation_interfaces/msg/Bounds");      // Spawnable's
  expect_hash("simulation_interfaces/msg/TagsFilter");  // GetAvailableWorlds'
}

// Each code is the definition's constant of that name, and every constant of those definitions
// has its code ("uint8 NAME = value" lines, comments cut off).
TEST(SimulationInterfacesCodec, SpawnAndWorldCodesAreTheDefinitions) {
  const auto constants = [](std::string_view type) {
    std::map<std::string, int, std::less<>> out;
    std::istringstream lines{std::string(definition(type))};
    for (std::string line; std::getline(lines, line);) {
      std::istringstream words(line.substr(0, line.find('#')));
      std::string kind, name, equals;
      int value = 0;
      if (words >> kind >> name >> equals >> value && equals == "=") {
        EXPECT_EQ(kind, "uint8") << type << ": " << line;
        out[name] = value;
      }
    }
    return out;
  };
  using Codes = std::map<std::string, int, std::less<>>;
  const auto spawn_codes = [](auto t) {
    using T = decltype(t);
    return Codes{{"NAME_NOT_UNIQUE", T::kNameNotUnique},
                 {"NAME_INVALID", T::kNameInvalid},
                 {"UNSUPPORTED_FORMAT", T::kUnsupportedFormat},
                 {"NO_RESOURCE", T::kNoResource},
                 {"NAMESPACE_INVALID", T::kNamespaceInvalid},
                 {"RESOURCE_PARSE_ERROR", T::kResourceParseError},
                 {"MISSING_ASSETS", T::kMissingAssets},
                 {"UNSUPPORTED_ASSETS", T::kUnsupportedAssets},
                 {"INVALID_POSE", T::kInvalidPose}};
  };
  using L = LoadWorldResponse;
  const std::vector<std::pair<std::string_view, Codes>> expected = {
      {SpawnResult::kType, spawn_codes(SpawnResult{})},
      {SpawnEntityRequest::kService, spawn_codes(SpawnEntityResponse{})},
      {SpawnEntitiesRequest::kService,
       {{"ENTITIES_SPAWN_FAILED", SpawnEntitiesResponse::kEntitiesSpawnFailed}}},
      {DeleteEntityRequest::kService, {}},
      {GetSpawnablesRequest::kService, {}},
      {LoadWorldRequest::kService,
       {{"UNSUPPORTED_FORMAT", L::kUnsupportedFormat},
        {"NO_RESOURCE", L::kNoResource},
        {"RESOURCE_PARSE_ERROR", L::kResourceParseError},
        {"MISSING_ASSETS", L::kMissingAssets},
        {"UNSUPPORTED_ASSETS", L::kUnsupportedAssets},
        {"UNSUPPORTED_ELEMENTS", L::kUnsupportedElements}}},
      {UnloadWorldRequest::kService, {{"NO_WORLD_LOADED", UnloadWorldResponse::kNoWorldLoaded}}},
      {GetCurrentWorldRequest::kService, {{"NO_WORLD_LOADED", GetCurrentWorldResponse::kNoWorldLoaded}}},
      {GetAvailableWorldsRequest::kService,
       {{"DEFAULT_SOURCES_FAILED", GetAvailableWorldsResponse::kDefaultSourcesFailed}}},
      {"simulation_interfaces/msg/TagsFilter",
       {{"FILTER_MODE_ANY", TagsFilter::kFilterModeAny}, {"FILTER_MODE_ALL", TagsFilter::kFilterModeAll}}},
  };
  for (const auto& [type, codes] : expected) {
    SCOPED_TRACE(type);
    ASSERT_FALSE(definition(type).empty());
    EXPECT_EQ(constants(type), codes);
  }
}

// Every prefix short of the data (the final padding aside) is refused naming the type; a length
// past the data, wherever it lands, is refused or read, never a crash or a huge allocation.
TEST(SimulationInterfacesCodec, SpawnAndWorldTruncatedOrHostileBytesAreRefused) {
  for_each_spawn_and_world_type([&]<class T>(const T& m, std::string_view half) {
    const std::string name = rosidl_name<T>(half);
    SCOPED_TRACE(name);
    Bytes cdr;
    encode(m, cdr);
    const std::size_t data = cdr.size() - static_cast<std::size_t>(cdr[3]);
    // "pkg/msg/Name", or "pkg/srv/Name request" as errors name a service's half.
    std::string named = name;
    if constexpr (requires { T::kService; }) {
      named = std::string(T::kService) + (half == "_Request" ? " request" : " response");
    }
    for (std::size_t n = 0; n < data; ++n) {
      T out;
      const Status st = decode(std::span<const std::byte>(cdr.data(), n), out);
      ASSERT_FALSE(st.ok()) << n << " of " << cdr.size() << " bytes decoded";
      EXPECT_NE(st.error().message.find(named), std::string::npos) << st.error().message;
    }
    for (std::size_t at = 4; at + 4 <= cdr.size(); at += 4) {
      Bytes hostile = cdr;
      for (std::size_t i = 0; i < 4; ++i)
        hostile[at + i] = std::byte{i == 3 ? std::uint8_t{0x7f} : std::uint8_t{0xff}};
      T out;
      (void)decode(hostile, out);
    }
  });
  // A count of two billion spawn requests in a short message fails before anything is allocated.
  Bytes hostile{std::byte{0},    std::byte{1},    std::byte{0},    std::byte{0},
                std::byte{0xff}, std::byte{0xff}, std::byte{0xff}, std::byte{0x7f}};
  SpawnEntitiesRequest spawns;
  const Status st = decode(hostile, spawns);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.error().message.find("simulation_interfaces/srv/SpawnEntities request"), std::string::npos)
      << st.error().message;
  EXPECT_TRUE(spawns.spawn_requests.empty());
}

// The wire layout of LoadWorld's request: two strings, then the two bools in definition order.
TEST(SimulationInterfacesCodec, LoadWorldBytesFollowTheDefinition) {
  Bytes cdr;
  encode(LoadWorldRequest{{"a", ""}, false, true}, cdr);
  // header, u32 2 "a\0" (padded to 8), u32 1 "\0", then the bools at offsets 13 and 14 of the body
  ASSERT_EQ(cdr.size(), 4u + 16u);
  std::uint32_t n = 0;
  std::memcpy(&n, cdr.data() + 4, 4);
  EXPECT_EQ(n, 2u);
  std::memcpy(&n, cdr.data() + 12, 4);
  EXPECT_EQ(n, 1u);
  EXPECT_EQ(cdr[4 + 13], std::byte{0});  // fail_on_unsupported_element
  EXPECT_EQ(cdr[4 + 14], std::byte{1});  // ignore_missing_or_unsupported_assets
}

}  // namespace
}  // namespace rbsim::msgs::simulation
