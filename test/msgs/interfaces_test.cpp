// The service and parameter codecs (rbsim/interfaces.hpp): round trips of every type, byte layouts
// derived by hand from the CDR rules, and malformed input (every truncation, corrupted and random
// bytes, huge lengths).
#include "rbsim/interfaces.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

namespace rbsim::msgs {
namespace {

Bytes bytes(std::initializer_list<int> v) {
  Bytes out;
  for (int b : v) out.push_back(static_cast<std::byte>(b));
  return out;
}

ParameterValue double_array_value() {
  ParameterValue v;
  v.type = ParameterType::DoubleArray;
  v.double_array_value = {1.5, -0.0, std::numeric_limits<double>::infinity()};
  return v;
}
// A value with every field set, so a field read from the wrong place shows.
ParameterValue full_value() {
  ParameterValue v;
  v.type = ParameterType::StringArray;
  v.bool_value = true;
  v.integer_value = -1234567890123;
  v.double_value = 2.5e-300;
  v.string_value = "forces.0.fy";
  v.byte_array_value = {0, 255, 7};
  v.bool_array_value = {true, false, true};
  v.integer_array_value = {INT64_MIN, 0, INT64_MAX};
  v.double_array_value = {-3.7, 1e300};
  v.string_array_value = {"", "a", "bc"};
  return v;
}
Parameter parameter(std::string name, ParameterValue v) {
  return Parameter{std::move(name), std::move(v)};
}
ParameterDescriptor descriptor() {
  ParameterDescriptor d;
  d.name = "rate";
  d.type = ParameterType::Double;
  d.description = "steps per second";
  d.additional_constraints = ">= 0";
  d.read_only = false;
  d.dynamic_typing = true;
  d.floating_point_range = FloatingPointRange{0.0, 1e6, 0.0};
  return d;
}
SetParametersRequest set_request() {
  return {{parameter("rate", double_array_value()), parameter("x", full_value()), parameter("", {})}};
}

template <class T>
void expect_round_trip(const T& m) {
  Bytes cdr;
  encode(m, cdr);
  ASSERT_GE(cdr.size(), 4u);
  EXPECT_EQ(cdr.size() % 4, 0u);
  T back;
  const Status st = decode(cdr, back);
  ASSERT_TRUE(st.ok()) << st.error().message;
  EXPECT_TRUE(back == m);
  // Re-encoding what was read gives the same bytes.
  Bytes again;
  encode(back, again);
  EXPECT_EQ(again, cdr);
}

CommandMessage command_message() {
  CommandMessage c;
  c.seq = 7;
  c.step = 1234;
  c.stamp = {1, 234000000};
  c.kind = CommandMessage::SetParameters;
  c.source = "script steer.yaml:3";
  c.parameters = {parameter("forces.0.fy", full_value())};
  c.atomic = false;
  c.steps = 5;
  c.pause_seconds = 0.25;
  c.body = 3;
  c.jx = 0.5, c.jy = -2.0, c.px = 0.1, c.py = 1e-300;
  c.success = true;
  c.message = "set 1 of 1 parameters at step 1234";
  return c;
}

TEST(InterfacesCodec, EveryTypeRoundTrips) {
  expect_round_trip(full_value());
  expect_round_trip(ParameterValue{});
  expect_round_trip(parameter("springs.3.k", full_value()));
  expect_round_trip(descriptor());
  ParameterDescriptor ints;
  ints.name = "publish_every";
  ints.integer_range = IntegerRange{1, INT64_MAX, 1};
  ints.read_only = true;
  expect_round_trip(ints);
  expect_round_trip(SetParametersResult{false, "rate: must be >= 0 (got -1)"});
  expect_round_trip(ListParametersResult{{"dt", "forces.0.fx"}, {"forces", "forces.0"}});
  ParameterEvent e;
  e.stamp = {12, 500000000};
  e.node = "/rbsim";
  e.changed_parameters = {parameter("rate", double_array_value())};
  e.new_parameters = {parameter("a", full_value()), parameter("b", {})};
  expect_round_trip(e);
  expect_round_trip(ListParametersRequest{{"forces", "springs.0"}, 2});
  expect_round_trip(ListParametersResponse{{{"x"}, {}}});
  expect_round_trip(GetParametersRequest{{"rate", "", "paused"}});
  expect_round_trip(GetParametersResponse{{full_value(), {}, double_array_value()}});
  expect_round_trip(set_request());
  expect_round_trip(SetParametersResponse{{{true, ""}, {false, "read-only"}}});
  expect_round_trip(SetParametersAtomicallyRequest{set_request().parameters});
  expect_round_trip(SetParametersAtomicallyResponse{{false, "dt is read-only"}});
  expect_round_trip(DescribeParametersRequest{{"rate"}});
  expect_round_trip(DescribeParametersResponse{{descriptor(), ints, {}}});
  expect_round_trip(GetParameterTypesRequest{{"a", "b"}});
  expect_round_trip(GetParameterTypesResponse{{1, 2, 3, 9, 0}});
  expect_round_trip(TriggerRequest{});
  expect_round_trip(TriggerResponse{true, "paused at step 120"});
  expect_round_trip(command_message());
  expect_round_trip(CommandMessage{});
  expect_round_trip(StepRequest{4000000000u});
  expect_round_trip(StepResponse{true, "stepped", 1ull << 40});
  expect_round_trip(ApplyImpulseRequest{7, 1.0, -2.0, 0.25, -0.125});
  expect_round_trip(ApplyImpulseResponse{false, "unknown body 7", 3});
  expect_round_trip(PauseRequest{});
  expect_round_trip(PauseResponse{});
  expect_round_trip(ResumeRequest{});
  expect_round_trip(ResumeResponse{});
  expect_round_trip(TogglePausedRequest{});
  expect_round_trip(TogglePausedResponse{});
  expect_round_trip(IsPausedRequest{});
  expect_round_trip(IsPausedResponse{true});
  expect_round_trip(GetRateRequest{});
  expect_round_trip(GetRateResponse{0.25});
  expect_round_trip(SetRateRequest{-3.5});
  expect_round_trip(SetRateResponse{true});
  expect_round_trip(SeekRequest{{-2, 999999999u}});
  expect_round_trip(SeekResponse{true});
  expect_round_trip(PlayNextRequest{});
  expect_round_trip(PlayNextResponse{true});
  expect_round_trip(BurstRequest{1ull << 40});
  expect_round_trip(BurstResponse{7});
  expect_round_trip(SnapshotRequest{});
  expect_round_trip(SnapshotResponse{true});
  expect_round_trip(SplitBagfileRequest{});
  expect_round_trip(SplitBagfileResponse{});
}

// rosbag2_interfaces (Jazzy): empty halves are the placeholder byte; Seek's builtin_interfaces/Time
// is int32 sec, uint32 nanosec; Burst's uint64 and SetRate's float64 start at offset 0.
TEST(InterfacesCodec, PlayerServicesLayout) {
  Bytes cdr;
  encode(PauseRequest{}, cdr);
  EXPECT_EQ(cdr, bytes({0, 1, 0, 3, 0, 0, 0, 0}));
  encode(ResumeResponse{}, cdr);
  EXPECT_EQ(cdr, bytes({0, 1, 0, 3, 0, 0, 0, 0}));
  encode(SeekRequest{{1, 2}}, cdr);
  EXPECT_EQ(cdr, bytes({0, 1, 0, 0, 1, 0, 0, 0, 2, 0, 0, 0}));
  encode(BurstRequest{5}, cdr);
  EXPECT_EQ(cdr, bytes({0, 1, 0, 0, 5, 0, 0, 0, 0, 0, 0, 0}));
  encode(SetRateRequest{1.0}, cdr);
  EXPECT_EQ(cdr, bytes({0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0xf0, 0x3f}));
  encode(IsPausedResponse{true}, cdr);
  EXPECT_EQ(cdr, bytes({0, 1, 0, 3, 1, 0, 0, 0}));
  encode(SnapshotResponse{true}, cdr);  // the recorder's
  EXPECT_EQ(cdr, bytes({0, 1, 0, 3, 1, 0, 0, 0}));
  encode(SplitBagfileRequest{}, cdr);
  EXPECT_EQ(cdr, bytes({0, 1, 0, 3, 0, 0, 0, 0}));
}

// CDR offsets count from the end of the 4-byte encapsulation header; the message is padded to a
// multiple of 4 with the pad count in the header's last byte.
TEST(InterfacesCodec, StepResponseAlignsTheUint64AfterTheString) {
  Bytes cdr;
  encode(StepResponse{true, "ab", 5}, cdr);
  // 0: bool 01, 1-3 pad, 4: length 3, 8: 'a' 'b' NUL, 11-15 pad to 8, 16: u64 5; 24 bytes, no pad.
  EXPECT_EQ(cdr,
            bytes({0, 1, 0, 0, 1, 0, 0, 0, 3, 0, 0, 0, 'a', 'b', 0, 0, 0, 0, 0, 0, 5, 0, 0, 0, 0, 0, 0, 0}));
}

TEST(InterfacesCodec, SetParametersResultLayout) {
  Bytes cdr;
  encode(SetParametersResult{true, "ok"}, cdr);
  // 0: bool, 1-3 pad, 4: length 3, 8: 'o' 'k' NUL; 11 bytes, 1 byte of padding (header byte 3 = 1).
  EXPECT_EQ(cdr, bytes({0, 1, 0, 1, 1, 0, 0, 0, 3, 0, 0, 0, 'o', 'k', 0, 0}));
}

TEST(InterfacesCodec, ListParametersRequestAlignsDepthAfterTheStrings) {
  Bytes cdr;
  encode(ListParametersRequest{{"x"}, 3}, cdr);
  // 0: count 1, 4: length 2, 8: 'x' NUL, 10-15 pad to 8, 16: u64 depth 3.
  EXPECT_EQ(cdr,
            bytes({0, 1, 0, 0, 1, 0, 0, 0, 2, 0, 0, 0, 'x', 0, 0, 0, 0, 0, 0, 0, 3, 0, 0, 0, 0, 0, 0, 0}));
}

TEST(InterfacesCodec, ParameterValueLayoutWithASequenceOfStrings) {
  ParameterValue v;
  v.type = ParameterType::StringArray;
  v.double_value = 1.0;
  v.string_array_value = {"a", "bc"};
  Bytes cdr;
  encode(v, cdr);
  // 0: type 09, 1: bool 00, 2-7 pad, 8: int64 0, 16: float64 1.0 (3ff0000000000000), 24: string
  // length 1, 28: NUL, 29-31 pad, 32/36/40/44: four empty sequences (no element, no alignment),
  // 48: count 2, 52: length 2, 56: 'a' NUL, 58-59 pad, 60: length 3, 64: 'b' 'c' NUL; 67 bytes,
  // one of padding.
  const Bytes expected = bytes({0, 1, 0, 1,                        // header, pad count 1
                                9, 0, 0, 0, 0,   0,   0,    0,     // 0
                                0, 0, 0, 0, 0,   0,   0,    0,     // 8
                                0, 0, 0, 0, 0,   0,   0xf0, 0x3f,  // 16
                                1, 0, 0, 0, 0,   0,   0,    0,     // 24
                                0, 0, 0, 0, 0,   0,   0,    0,    0,   0, 0, 0, 0, 0, 0, 0,  // 32
                                2, 0, 0, 0, 2,   0,   0,    0,    'a', 0, 0, 0,              // 48
                                3, 0, 0, 0, 'b', 'c', 0,    0});                             // 60
  EXPECT_EQ(cdr, expected);
}

TEST(InterfacesCodec, CommandMessageLayout) {
  CommandMessage c;
  c.seq = 2;
  c.step = 9;
  c.kind = CommandMessage::ApplyImpulse;
  c.source = "ab";  // u32 length 3, "ab\0"
  c.body = 4;
  c.jx = 1.0;
  c.success = true;
  Bytes cdr;
  encode(c, cdr);
  // Offsets after the 4-byte header: sequence 0, step 8, stamp 16 (int32, uint32), kind 24, source
  // length 28 and text 32..34, parameters length 36, atomic 40, steps 48, pause_seconds 56, body 64,
  // jx 72, jy 80, px 88, py 96, success 104, message length 108 (0 + its nul: 1).
  ASSERT_EQ(cdr.size(), 4u + 116);
  EXPECT_EQ(cdr[4 + 0], std::byte{2});
  EXPECT_EQ(cdr[4 + 8], std::byte{9});
  EXPECT_EQ(cdr[4 + 24], std::byte{5});
  EXPECT_EQ(cdr[4 + 28], std::byte{3});
  EXPECT_EQ(cdr[4 + 32], std::byte{'a'});
  EXPECT_EQ(cdr[4 + 40], std::byte{1});  // atomic: true by default
  EXPECT_EQ(cdr[4 + 64], std::byte{4});
  EXPECT_EQ(cdr[4 + 79], std::byte{0x3f});  // jx = 1.0: top byte
  EXPECT_EQ(cdr[4 + 104], std::byte{1});
  EXPECT_EQ(cdr[4 + 108], std::byte{1});
}

TEST(InterfacesCodec, TriggerRequestIsOnePlaceholderByte) {
  Bytes cdr;
  encode(TriggerRequest{}, cdr);
  EXPECT_EQ(cdr, bytes({0, 1, 0, 3, 0, 0, 0, 0}));
}

TEST(InterfacesCodec, ApplyImpulseRequestLayout) {
  Bytes cdr;
  encode(ApplyImpulseRequest{2, 1.0, 0, 0, -2.0}, cdr);
  ASSERT_EQ(cdr.size(), 4u + 8 + 32);  // u32 body, 4 pad, four float64 at 8, 16, 24, 32
  EXPECT_EQ(cdr[4], std::byte{2});
  EXPECT_EQ(cdr[4 + 15], std::byte{0x3f});  // jx = 1.0: top byte at offset 15
  EXPECT_EQ(cdr[4 + 39], std::byte{0xc0});  // py = -2.0: top byte at offset 39
}

// Every prefix shorter than the data (the trailing padding aside) fails with an error naming the
// type and where the data ran out.
template <class T>
void expect_every_truncation_fails(const T& m, std::string_view name) {
  Bytes cdr;
  encode(m, cdr);
  const std::size_t data_end = cdr.size() - static_cast<std::size_t>(cdr[3]);
  for (std::size_t n = 0; n < data_end; ++n) {
    T out;
    const Status st = decode(std::span<const std::byte>(cdr.data(), n), out);
    ASSERT_FALSE(st.ok()) << name << " cut at " << n << " of " << cdr.size();
    EXPECT_NE(st.error().message.find(name), std::string::npos) << st.error().message;
  }
}

TEST(InterfacesCodec, EveryTruncationOfAValidMessageFails) {
  expect_every_truncation_fails(set_request(), "rcl_interfaces/srv/SetParameters request");
  expect_every_truncation_fails(SetParametersAtomicallyRequest{set_request().parameters},
                                "rcl_interfaces/srv/SetParametersAtomically request");
  expect_every_truncation_fails(ListParametersRequest{{"forces", "x"}, 1},
                                "rcl_interfaces/srv/ListParameters request");
  expect_every_truncation_fails(GetParametersRequest{{"rate", "dt"}},
                                "rcl_interfaces/srv/GetParameters request");
  expect_every_truncation_fails(DescribeParametersResponse{{descriptor()}}, "DescribeParameters response");
  expect_every_truncation_fails(StepRequest{3}, "rbsim_msgs/srv/Step request");
  expect_every_truncation_fails(ApplyImpulseRequest{1, 2, 3, 4, 5}, "rbsim_msgs/srv/ApplyImpulse request");
  expect_every_truncation_fails(TriggerRequest{}, "std_srvs/srv/Trigger request");
  expect_every_truncation_fails(TriggerResponse{true, "x"}, "std_srvs/srv/Trigger response");
  expect_every_truncation_fails(PauseRequest{}, "rosbag2_interfaces/srv/Pause request");
  expect_every_truncation_fails(SeekRequest{{3, 4}}, "rosbag2_interfaces/srv/Seek request");
  expect_every_truncation_fails(SetRateRequest{2.0}, "rosbag2_interfaces/srv/SetRate request");
  expect_every_truncation_fails(BurstRequest{9}, "rosbag2_interfaces/srv/Burst request");
  expect_every_truncation_fails(GetRateResponse{2.0}, "rosbag2_interfaces/srv/GetRate response");
  ParameterEvent e;
  e.node = "/rbsim";
  e.changed_parameters = {parameter("rate", full_value())};
  expect_every_truncation_fails(e, "rcl_interfaces/msg/ParameterEvent");
  expect_every_truncation_fails(command_message(), "rbsim_msgs/msg/Command");
}

TEST(InterfacesCodec, ErrorNamesTheOffset) {
  Bytes cdr;
  encode(StepResponse{true, "abc", 1}, cdr);
  // Body: bool at 0, length 4 at 4, "abc" NUL at 8..11, u64 at 16 (message bytes 20..27). Cut at
  // 20, the u64 (with its padding from message byte 16) does not fit: the read at byte 16 fails.
  cdr.resize(20);
  StepResponse out;
  const Status st = decode(cdr, out);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.error().message.find("at byte 16 of 20"), std::string::npos) << st.error().message;
}

TEST(InterfacesCodec, WrongEncapsulationIsRefused) {
  Bytes cdr;
  encode(StepRequest{1}, cdr);
  cdr[1] = std::byte{0};  // CDR_BE
  StepRequest out;
  const Status st = decode(cdr, out);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.error().message.find("not plain little-endian CDR"), std::string::npos);
}

// A sequence count far beyond the bytes left fails before anything is allocated.
TEST(InterfacesCodec, HugeLengthsFailWithoutAllocating) {
  for (std::uint32_t n : {0xffffffffu, 0x10000000u, 3u}) {
    Bytes cdr = bytes({0, 1, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 'x', 0, 0, 0});
    std::memcpy(cdr.data() + 4, &n, 4);  // the count of names
    GetParametersRequest out;
    EXPECT_FALSE(decode(cdr, out).ok()) << n;
    SetParametersRequest sp;
    EXPECT_FALSE(decode(cdr, sp).ok()) << n;
    GetParameterTypesResponse types;
    if (n > 8) {
      EXPECT_FALSE(decode(cdr, types).ok()) << n;
    }
  }
}

// A descriptor's ranges are bounded sequences of at most one element.
TEST(InterfacesCodec, DescriptorWithTwoRangesIsRefused) {
  ParameterDescriptor d = descriptor();
  d.floating_point_range.reset();
  Bytes cdr;
  encode(d, cdr);
  // Without ranges the message ends with the two counts (u32 0, u32 0).
  ASSERT_EQ(cdr[3], std::byte{0});
  const std::size_t count_at = cdr.size() - 8;
  ParameterDescriptor out;
  ASSERT_TRUE(decode(cdr, out).ok());
  // Two float ranges: count 2, then (aligned to 8) 48 bytes of float64s, then the integer count 0.
  cdr.resize(count_at);
  const std::uint32_t two = 2;
  cdr.resize(count_at + 4 + 4 + 48 + 4, std::byte{0});
  std::memcpy(cdr.data() + count_at, &two, 4);
  const Status st = decode(cdr, out);
  EXPECT_FALSE(st.ok());
  // The same bytes with count 1 and one range are fine: the refusal is the bound.
  const std::uint32_t one = 1;
  std::memcpy(cdr.data() + count_at, &one, 4);
  cdr.resize(count_at + 4 + 4 + 24 + 4);
  EXPECT_TRUE(decode(cdr, out).ok());
  EXPECT_TRUE(out.floating_point_range.has_value());
}

// Random and corrupted bytes: decode returns, ok or not (a crash, a hang or a huge allocation
// fails the test; the sanitizer stage checks every read).
TEST(InterfacesCodec, RandomAndCorruptedBytesNeverCrash) {
  std::mt19937 rng(22);
  Bytes valid;
  encode(set_request(), valid);
  std::size_t refused = 0;
  for (int i = 0; i < 3000; ++i) {
    Bytes cdr;
    if (i % 2 == 0) {
      cdr = valid;
      for (int k = 0; k < 4; ++k) cdr[4 + rng() % (cdr.size() - 4)] = static_cast<std::byte>(rng());
    } else {
      cdr.resize(rng() % 200);
      for (auto& b : cdr) b = static_cast<std::byte>(rng());
      if (cdr.size() >= 2 && i % 4 == 1) cdr[0] = std::byte{0}, cdr[1] = std::byte{1};
    }
    SetParametersRequest a;
    ParameterEvent b;
    DescribeParametersResponse c;
    ApplyImpulseRequest d;
    refused += !decode(cdr, a).ok();
    refused += !decode(cdr, b).ok();
    refused += !decode(cdr, c).ok();
    refused += !decode(cdr, d).ok();
  }
  EXPECT_GT(refused, 0u);
}

}  // namespace
}  // namespace rbsim::msgs
