// simulation_interfaces' codecs (rbsim/simulation_interfaces.hpp): every type round-trips through
// its CDR, the bytes follow the definition's field order and alignment, and untrusted bytes
// (truncated, a length past the data, a wrong header) are errors naming the type, never a crash.
#include "rbsim/simulation_interfaces.hpp"

#include <gtest/gtest.h>

#include <cstring>

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

}  // namespace
}  // namespace rbsim::msgs::simulation
