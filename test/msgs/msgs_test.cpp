#include <gtest/gtest.h>

#include <array>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>

#include "decoder_for.hpp"
#include "rbsim/builders.hpp"
#include "rbsim/cdr.hpp"
#include "rbsim/cdr_builder.hpp"
#include "rbsim/interfaces.hpp"
#include "rbsim/msgs.hpp"

namespace {

using rbsim::msgs::Scalar;
using rbsim::msgs::TopicId;

rbsim::Scene spring_wind_scene() {
  rbsim::Scene scene;
  scene.name = "unit";
  scene.description = "two bodies, a spring, gravity and wind";
  scene.world = rbsim::builders::grid(3, /*wind_and_springs=*/true);
  scene.duration = 1.0;
  for (int b = 0; b < 3; ++b) scene.body_colors.push_back(rbsim::default_body_color(b));
  scene.spring_colors.assign(3, rbsim::Color{0.1, 0.2, 0.3});
  return scene;
}

// builtin_interfaces/Time from a count of ns: whole seconds and the rest, at the edges.
TEST(TimeFromNs, SplitsSecondsAndNanoseconds) {
  EXPECT_EQ(rbsim::msgs::time_from_ns(0), (rbsim::msgs::Time{0, 0}));
  EXPECT_EQ(rbsim::msgs::time_from_ns(999'999'999), (rbsim::msgs::Time{0, 999'999'999}));
  EXPECT_EQ(rbsim::msgs::time_from_ns(1'000'000'000), (rbsim::msgs::Time{1, 0}));
  EXPECT_EQ(rbsim::msgs::time_from_ns(1'765'000'000'123'456'789),
            (rbsim::msgs::Time{1'765'000'000, 123'456'789}));
  EXPECT_EQ(rbsim::msgs::sim_time(3, 0.5), rbsim::msgs::time_from_ns(1'500'000'000));  // one split for both
}

TEST(TopicNames, FollowRos2Conventions) {
  const auto& states = rbsim::msgs::topic(TopicId::BodyStates);
  EXPECT_EQ(rbsim::msgs::topic_name(states, "rbsim"), "/rbsim/body_states");
  EXPECT_EQ(rbsim::msgs::topic_name(states, "/a/b/"), "/a/b/body_states");
  EXPECT_EQ(rbsim::msgs::topic_name(rbsim::msgs::topic(TopicId::Clock), "rbsim"), "/clock");
  EXPECT_EQ(rbsim::msgs::dds_topic_name("/rbsim/body_states"), "rt/rbsim/body_states");
  EXPECT_EQ(rbsim::msgs::dds_type_name("rbsim_msgs/msg/BodyStates"), "rbsim_msgs::msg::dds_::BodyStates_");
  EXPECT_EQ(rbsim::msgs::dds_type_name("geometry_msgs/PoseArray"), "geometry_msgs::msg::dds_::PoseArray_");
}

TEST(TopicNames, NamesTopicTakesTheWholeNameOrItsTrailingParts) {
  using rbsim::msgs::names_topic;
  EXPECT_TRUE(names_topic("/rbsim/body_states", "/rbsim/body_states"));
  EXPECT_TRUE(names_topic("body_states", "/rbsim/body_states"));
  EXPECT_TRUE(names_topic("rbsim/body_states", "/rbsim/body_states"));
  EXPECT_TRUE(names_topic("clock", "/clock"));
  EXPECT_FALSE(names_topic("states", "/rbsim/body_states"));  // not a whole part
  EXPECT_FALSE(names_topic("/body_states", "/rbsim/body_states"));
  EXPECT_FALSE(names_topic("", "/clock"));
  EXPECT_FALSE(names_topic("/clock", "clock"));
}

TEST(TopicNames, TopicForTypeFindsOursInEitherSpelling) {
  EXPECT_EQ(rbsim::msgs::topic_for_type("rbsim_msgs/msg/BodyStates"),
            &rbsim::msgs::topic(TopicId::BodyStates));
  EXPECT_EQ(rbsim::msgs::topic_for_type("rosgraph_msgs/Clock"), &rbsim::msgs::topic(TopicId::Clock));
  EXPECT_EQ(rbsim::msgs::topic_for_type("std_msgs/msg/String"), nullptr);
}

TEST(Ros2msgSchema, AppendsEachDependencyOnceRosbag2Style) {
  auto schema = rbsim::msgs::ros2msg_schema("rbsim_msgs/msg/BodyStates");
  ASSERT_TRUE(schema.ok());
  const std::string& s = schema.value();
  EXPECT_TRUE(s.starts_with(rbsim::msgs::definition("rbsim_msgs/msg/BodyStates")));
  const std::string bar = "\n" + std::string(80, '=') + "\nMSG: ";
  for (const char* dep : {"std_msgs/Header", "builtin_interfaces/Time", "rbsim_msgs/BodyState"}) {
    const auto at = s.find(bar + dep + "\n");
    ASSERT_NE(at, std::string::npos) << dep;
    EXPECT_EQ(s.find(bar + dep + "\n", at + 1), std::string::npos) << dep << " appears twice";
  }
  // rosbag2 visits dependencies in sorted order, depth first: rbsim_msgs/BodyState sorts before
  // std_msgs/Header, whose own dependency builtin_interfaces/Time follows it.
  EXPECT_LT(s.find("MSG: rbsim_msgs/BodyState"), s.find("MSG: std_msgs/Header"));
  EXPECT_LT(s.find("MSG: std_msgs/Header"), s.find("MSG: builtin_interfaces/Time"));
  EXPECT_FALSE(rbsim::msgs::ros2msg_schema("nope_msgs/msg/Nothing").ok());
}

TEST(Ros2msgSchema, EveryTopicTypeResolves) {
  for (const auto& t : rbsim::msgs::topics()) {
    auto schema = rbsim::msgs::ros2msg_schema(t.type);
    ASSERT_TRUE(schema.ok()) << t.type;
    EXPECT_TRUE(rbsim::msgs::MessageDecoder::create(t.type, schema.value()).ok()) << t.type;
  }
}

TEST(ParseMsgFields, ReadsArraysNestedTypesAndSkipsConstants) {
  using rbsim::msgs::MsgField;
  const auto fields = rbsim::msgs::parse_msg_fields("pkg/msg/T", R"(# a comment line
int32 LIMIT=3
string NAME = "x"   # a constant with spaces
float64 x   # trailing comment
uint8[4] fixed
string<=8[] names
Header header
other_pkg/Thing[<=2] things
Local[] locals
)");
  ASSERT_TRUE(fields.ok()) << fields.error().message;
  const std::vector<MsgField>& f = fields.value();
  ASSERT_EQ(f.size(), 6u);
  EXPECT_EQ(f[0].name, "x");
  ASSERT_TRUE(f[0].primitive.has_value());
  EXPECT_EQ(f[0].primitive->kind, Scalar::Kind::Float);
  EXPECT_EQ(f[0].primitive->size, 8);
  EXPECT_EQ(f[1].array, MsgField::Array::Fixed);
  EXPECT_EQ(f[1].fixed_size, 4u);
  EXPECT_EQ(f[2].array, MsgField::Array::Sequence);
  EXPECT_EQ(f[2].primitive->size, 0) << "a bounded string is a string";
  EXPECT_EQ(f[3].type, "std_msgs/msg/Header");
  EXPECT_FALSE(f[3].primitive.has_value());
  EXPECT_EQ(f[4].type, "other_pkg/msg/Thing");
  EXPECT_EQ(f[4].array, MsgField::Array::Sequence);
  EXPECT_EQ(f[5].type, "pkg/msg/Local");

  // rosidl's member for an empty message
  const auto empty = rbsim::msgs::parse_msg_fields("pkg/msg/Empty", "# nothing\n");
  ASSERT_TRUE(empty.ok());
  ASSERT_EQ(empty.value().size(), 1u);
  EXPECT_EQ(empty.value()[0].name, "structure_needs_at_least_one_member");
  EXPECT_EQ(empty.value()[0].primitive->size, 1);

  for (const char* bad :
       {"float64", "uint8[3x] a", "uint8[-1] a", "uint8[99999999999] a", "uint8[3 a", "wstring w"}) {
    const auto r = rbsim::msgs::parse_msg_fields("pkg/msg/Bad", bad);
    EXPECT_FALSE(r.ok()) << bad;
    if (!r.ok()) {
      EXPECT_TRUE(r.error().message.starts_with("pkg/msg/Bad: ")) << r.error().message;
    }
  }
}

// Hand-encoded: header 00 01 00 00, sec = 1 (int32), nanosec = 500000000 = 0x1DCD6500 (uint32).
TEST(EncoderClock, MatchesHandEncodedCdr) {
  rbsim::Scene scene = spring_wind_scene();
  scene.world.dt = 0.5;
  auto w = rbsim::World::create(scene.world);
  ASSERT_TRUE(w.ok());
  w->step();
  w->step();
  w->step();
  rbsim::msgs::Bytes out;
  rbsim::msgs::Encoder(scene).clock(w.value(), out);
  const std::vector<int> expected = {0, 1, 0, 0, 1, 0, 0, 0, 0x00, 0x65, 0xCD, 0x1D};
  ASSERT_EQ(out.size(), expected.size());
  for (std::size_t i = 0; i < out.size(); ++i)
    EXPECT_EQ(static_cast<int>(out[i]), expected[i]) << "byte " << i;
}

// rbsim replay's /clock for a log time, byte for byte what it wrote by hand before encode_clock
// (CDR_LE header, int32 sec, uint32 nanosec), and reusing the buffer it is given.
TEST(EncodeClock, IsWhatReplayWroteByHand) {
  auto by_hand = [](std::uint64_t t_ns) {
    std::array<std::byte, 12> out{};
    out[1] = std::byte{1};
    const auto sec = static_cast<std::int32_t>(t_ns / 1'000'000'000);
    const auto nsec = static_cast<std::uint32_t>(t_ns % 1'000'000'000);
    std::memcpy(out.data() + 4, &sec, 4);
    std::memcpy(out.data() + 8, &nsec, 4);
    return out;
  };
  rbsim::msgs::Bytes out(40, std::byte{0xAB});  // a longer message before: replaced, not appended to
  for (std::uint64_t t :
       {std::uint64_t{0}, std::uint64_t{1}, std::uint64_t{999'999'999}, std::uint64_t{1'500'000'000},
        std::uint64_t{1'700'000'000'123'456'789}, std::uint64_t{2'147'483'647'999'999'999}}) {
    const rbsim::msgs::Bytes& cdr = rbsim::msgs::encode_clock(t, out);
    EXPECT_EQ(&cdr, &out);
    const auto expected = by_hand(t);
    ASSERT_EQ(out.size(), expected.size()) << t;
    EXPECT_EQ(std::memcmp(out.data(), expected.data(), expected.size()), 0) << t;
  }
}

TEST(EncoderBodyStates, DecodesToTheWorldState) {
  rbsim::Scene scene = spring_wind_scene();
  auto w = rbsim::World::create(scene.world);
  ASSERT_TRUE(w.ok());
  for (int i = 0; i < 7; ++i) w->step();
  rbsim::msgs::Bytes out;
  rbsim::msgs::Encoder(scene).body_states(w.value(), out);
  std::vector<Scalar> v;
  const auto d = decoder_for(TopicId::BodyStates);
  ASSERT_TRUE(d.decode(out, v).ok());
  // header.stamp.sec, .nanosec, frame_id, step, bodies.length, then 7 per body
  ASSERT_EQ(v.size(), 5u + 7u * 3u);
  EXPECT_EQ(v[0].i, 0);
  EXPECT_EQ(v[1].u, 7'000'000u);  // 7 steps of 1 ms
  EXPECT_EQ(v[2].s, "world");
  EXPECT_EQ(v[3].u, 7u);
  EXPECT_EQ(v[4].u, 3u);
  for (int b = 0; b < 3; ++b) {
    const auto s = w->state(rbsim::BodyId{b});
    const std::size_t at = 5 + 7 * static_cast<std::size_t>(b);
    EXPECT_EQ(v[at].i, b);
    EXPECT_EQ(v[at + 1].f, s.position.x());
    EXPECT_EQ(v[at + 2].f, s.position.y());
    EXPECT_EQ(v[at + 3].f, s.theta);
    EXPECT_EQ(v[at + 4].f, s.velocity.x());
    EXPECT_EQ(v[at + 5].f, s.velocity.y());
    EXPECT_EQ(v[at + 6].f, s.omega);
  }
  EXPECT_EQ(d.path(out, 5 + 7 * 2 + 3), "bodies[2].theta");
  EXPECT_EQ(d.path(out, 4), "bodies.length");
  EXPECT_EQ(d.path(out, 1), "header.stamp.nanosec");
}

TEST(EncoderEnergy, TotalsMatchWorldEnergy) {
  rbsim::Scene scene = spring_wind_scene();
  auto w = rbsim::World::create(scene.world);
  ASSERT_TRUE(w.ok());
  for (int i = 0; i < 5; ++i) w->step();
  rbsim::msgs::Bytes out;
  rbsim::msgs::Encoder(scene).energy(w.value(), out);
  std::vector<Scalar> v;
  ASSERT_TRUE(decoder_for(TopicId::Energy).decode(out, v).ok());
  const rbsim::Energy e = w->energy();
  // the scalars at the end: momentum.x, momentum.y, angular, potential, kinetic_point, kinetic_spin,
  // total, potential_gravity, potential_spring
  const std::size_t n = v.size() - 2;
  EXPECT_EQ(v[n].f, e.u_gravity);  // the world's own sums, bit for bit
  EXPECT_EQ(v[n + 1].f, e.u_spring);
  EXPECT_NEAR(v[n - 4].f, e.potential(), 1e-12 * std::abs(e.potential()) + 1e-15);
  EXPECT_DOUBLE_EQ(v[n - 3].f, e.t_point);
  EXPECT_DOUBLE_EQ(v[n - 2].f, e.t_spin);
  EXPECT_NEAR(v[n - 1].f, e.total(), 1e-12 * std::abs(e.total()) + 1e-15);
}

TEST(EncoderPoses, QuaternionEncodesTheta) {
  rbsim::Scene scene = spring_wind_scene();
  auto w = rbsim::World::create(scene.world);
  ASSERT_TRUE(w.ok());
  for (int i = 0; i < 50; ++i) w->step();
  rbsim::msgs::Bytes out;
  rbsim::msgs::Encoder(scene).poses(w.value(), out);
  std::vector<Scalar> v;
  ASSERT_TRUE(decoder_for(TopicId::Poses).decode(out, v).ok());
  ASSERT_EQ(v[3].u, 3u);
  for (int b = 0; b < 3; ++b) {
    const std::size_t at = 4 + 7 * static_cast<std::size_t>(b);
    EXPECT_EQ(v[at].f, w->x()[b]);
    EXPECT_EQ(v[at + 1].f, w->y()[b]);
    EXPECT_NEAR(2.0 * std::atan2(v[at + 5].f, v[at + 6].f), w->theta()[b], 1e-12);
  }
}

TEST(EncoderMarkersAndScene, DecodeCleanly) {
  rbsim::Scene scene = spring_wind_scene();
  auto w = rbsim::World::create(scene.world);
  ASSERT_TRUE(w.ok());
  rbsim::msgs::Encoder enc(scene);
  for (TopicId id : {TopicId::Markers, TopicId::SceneDescription, TopicId::SpringStates}) {
    rbsim::msgs::Bytes out;
    enc.encode(id, w.value(), out);
    std::vector<Scalar> v;
    ASSERT_TRUE(decoder_for(id).decode(out, v).ok()) << rbsim::msgs::topic(id).suffix;
  }
  rbsim::msgs::Bytes out;
  enc.markers(w.value(), out);
  std::vector<Scalar> v;
  ASSERT_TRUE(decoder_for(TopicId::Markers).decode(out, v).ok());
  // three hulls filled and outlined, and the fixed spring anchors
  EXPECT_EQ(v[0].u, 7u);
}

using rbsim::test::Cdr;

// The one CDR cursor (rbsim/cdr.hpp) that every CDR reader walks with.
TEST(CdrCursor, AlignsFromTheEndOfTheHeaderAndNeverReadsPastTheData) {
  using rbsim::msgs::CdrCursor;
  Cdr c;
  c.put<std::uint8_t>(7).put(2.5).put<std::uint16_t>(3);  // 1 byte, 7 of padding, 8, 2
  ASSERT_EQ(c.bytes.size(), 22u);
  EXPECT_TRUE(CdrCursor::plain_header(c.bytes));
  CdrCursor at(c.bytes);
  EXPECT_EQ(at.pos(), 4u);
  std::uint8_t u8 = 0;
  ASSERT_TRUE(at.read(u8));
  EXPECT_EQ(u8, 7u);
  EXPECT_EQ(at.offset(), 1u);
  EXPECT_FALSE(at.align(8, 2));  // one double fits, two do not: the cursor stays
  EXPECT_EQ(at.offset(), 1u);
  double d = 0;
  ASSERT_TRUE(at.read(d));
  EXPECT_EQ(d, 2.5);
  EXPECT_EQ(at.pos(), 20u);
  std::uint16_t u16 = 0;
  ASSERT_TRUE(at.read(u16));
  EXPECT_EQ(u16, 3u);
  EXPECT_EQ(at.remaining(), 0u);
  std::uint32_t more = 0;
  EXPECT_FALSE(at.u32(more));
  EXPECT_TRUE(at.align(2, 0));   // no values, no padding: fits at the end
  EXPECT_FALSE(at.align(4, 0));  // the padding alone runs past the end
  EXPECT_EQ(at.pos(), 22u);

  CdrCursor skip(c.bytes);
  EXPECT_TRUE(skip.skip(1, 1));
  EXPECT_FALSE(skip.skip(8, 2));
  EXPECT_TRUE(skip.skip(8, 1));
  EXPECT_EQ(skip.pos(), 20u);
  EXPECT_FALSE(skip.skip(2, 2));
  EXPECT_TRUE(skip.skip(2, 1));
}

TEST(CdrCursor, StringsCarryTheirNulAndFitTheData) {
  using rbsim::msgs::CdrCursor;
  Cdr c;
  c.str("abc").str("");
  CdrCursor at(c.bytes);
  std::string_view s;
  ASSERT_TRUE(at.string(s));
  EXPECT_EQ(s, "abc");
  ASSERT_TRUE(at.string(s));
  EXPECT_EQ(s, "");
  EXPECT_EQ(at.remaining(), 0u);
  Cdr zero;  // a length of 0 (no NUL) and a length past the data are both malformed
  zero.put<std::uint32_t>(0);
  CdrCursor z(zero.bytes);
  EXPECT_FALSE(z.string(s));
  Cdr past;
  past.put<std::uint32_t>(5).put<std::uint8_t>('a');
  CdrCursor p(past.bytes);
  EXPECT_FALSE(p.string(s));
  const rbsim::msgs::Bytes big_endian{std::byte{0}, std::byte{0}, std::byte{0}, std::byte{0}};
  EXPECT_FALSE(CdrCursor::plain_header(big_endian));
  EXPECT_FALSE(CdrCursor::plain_header(std::span(c.bytes).first(3)));
}

TEST(MessageDecoder, ToJsonNestsObjectsAndArraysAndWritesNoNaN) {
  const char* schema =
      "float64 x\nfloat32 f\nstring name\nint32[] ids\nInner[2] pts\nbool ok\nuint8[] empty\n"
      "================================================================================\n"
      "MSG: test_msgs/Inner\nfloat64 a\n";
  auto d = rbsim::msgs::MessageDecoder::create("test_msgs/msg/T", schema);
  ASSERT_TRUE(d.ok()) << d.error().message;
  Cdr c;
  c.put(1.5).put(0.1f).str("a\"b\\c\n\x01").put<std::uint32_t>(2).put<std::int32_t>(-1).put<std::int32_t>(7);
  c.put(std::nan(""))
      .put(-std::numeric_limits<double>::infinity())
      .put<std::uint8_t>(1)
      .put<std::uint32_t>(0);
  std::string out = "prefix ";
  const auto st = d->to_json(c.bytes, out);
  ASSERT_TRUE(st.ok()) << st.error().message;
  EXPECT_EQ(out,
            "prefix {\"x\":1.5,\"f\":0.1,\"name\":\"a\\\"b\\\\c\\n\\u0001\",\"ids\":[-1,7],"
            "\"pts\":[{\"a\":null},{\"a\":null}],\"ok\":true,\"empty\":[]}");
  // malformed data: an error, and `out` as it was
  out = "kept";
  EXPECT_FALSE(d->to_json(std::span(c.bytes).first(c.bytes.size() - 2), out).ok());
  EXPECT_EQ(out, "kept");
}

TEST(MessageDecoder, ToJsonOfBodyStatesCarriesTheStatesValues) {
  rbsim::Scene scene = spring_wind_scene();
  auto w = rbsim::World::create(scene.world);
  ASSERT_TRUE(w.ok());
  rbsim::msgs::Bytes bytes;
  rbsim::msgs::Encoder(scene).encode(TopicId::BodyStates, w.value(), bytes);
  std::string json;
  ASSERT_TRUE(decoder_for(TopicId::BodyStates).to_json(bytes, json).ok());
  char x[64];
  const auto r = std::to_chars(x, x + sizeof x, w->x()[1]);
  EXPECT_NE(json.find("{\"id\":1,\"x\":" + std::string(x, r.ptr) + ","), std::string::npos) << json;
  EXPECT_EQ(json.rfind("{\"header\":{\"stamp\":{\"sec\":0,\"nanosec\":0},\"frame_id\":", 0), 0u) << json;
}

TEST(MessageDecoder, RejectsEveryTruncationAndSurvivesMutation) {
  rbsim::Scene scene = spring_wind_scene();
  auto w = rbsim::World::create(scene.world);
  ASSERT_TRUE(w.ok());
  rbsim::msgs::Bytes good;
  rbsim::msgs::Encoder(scene).scene(w.value(), good);
  const auto d = decoder_for(TopicId::SceneDescription);
  std::vector<Scalar> v;
  for (std::size_t n = 0; n < good.size(); ++n) {
    EXPECT_FALSE(d.decode(std::span(good).first(n), v).ok()) << "prefix " << n;
  }
  std::mt19937 rng(12345);
  for (int trial = 0; trial < 2000; ++trial) {
    rbsim::msgs::Bytes bad = good;
    bad[rng() % bad.size()] = static_cast<std::byte>(rng() & 0xFF);
    (void)d.decode(bad, v);  // either outcome is fine; it must not crash or hang
  }
}

}  // namespace

namespace {

TEST(DecodeScene, RoundTripsTheEncodedDescription) {
  rbsim::Scene scene = spring_wind_scene();
  scene.viewport = rbsim::Viewport{1.5, -2.0, 7.0};
  auto w = rbsim::World::create(scene.world);
  ASSERT_TRUE(w.ok());
  rbsim::msgs::Bytes out;
  rbsim::msgs::Encoder(scene).scene(w.value(), out);
  auto m = rbsim::msgs::decode_scene(out);
  ASSERT_TRUE(m.ok()) << m.error().message;
  EXPECT_EQ(m->name, "unit");
  EXPECT_EQ(m->integrator, "symplectic-euler");
  EXPECT_EQ(m->dt, scene.world.dt);
  ASSERT_EQ(m->bodies.size(), 3u);
  for (std::int32_t b = 0; b < 3; ++b) {
    EXPECT_EQ(m->bodies[b].mass, w->mass(rbsim::BodyId{b}));
    EXPECT_EQ(m->bodies[b].inertia, w->inertia(rbsim::BodyId{b}));
    const auto hull = w->hull(rbsim::BodyId{b});
    ASSERT_EQ(m->bodies[b].hull.size(), hull.size());
    for (std::size_t v = 0; v < hull.size(); ++v) EXPECT_EQ(m->bodies[b].hull[v], hull[v]);
    EXPECT_EQ(m->bodies[b].color.r, static_cast<float>(scene.body_colors[b].r));
  }
  ASSERT_EQ(m->springs.size(), 3u);
  EXPECT_EQ(m->springs[2].body_j, rbsim::kFixed);
  EXPECT_EQ(m->springs[0].stiffness, 10.0);
  ASSERT_EQ(m->winds.size(), 1u);
  EXPECT_EQ(m->winds[0].points_per_edge, 4);
  ASSERT_TRUE(m->viewport.has_value());
  EXPECT_EQ(m->viewport->size, 7.0);
  for (std::size_t n = 0; n + 1 < out.size(); n += 7)
    EXPECT_FALSE(rbsim::msgs::decode_scene(std::span(out).first(n)).ok());
}

TEST(DecodeBodyStates, RoundTripsAndRejectsTruncation) {
  rbsim::Scene scene = spring_wind_scene();
  auto w = rbsim::World::create(scene.world);
  ASSERT_TRUE(w.ok());
  for (int i = 0; i < 11; ++i) w->step();
  rbsim::msgs::Bytes out;
  rbsim::msgs::Encoder(scene).body_states(w.value(), out);
  rbsim::msgs::BodyStatesMessage m;
  ASSERT_TRUE(rbsim::msgs::decode_body_states(out, m).ok());
  EXPECT_EQ(m.step, 11u);
  ASSERT_EQ(m.bodies.size(), 3u);
  for (std::int32_t b = 0; b < 3; ++b) {
    EXPECT_EQ(m.bodies[b].id, b);
    const auto s = w->state(rbsim::BodyId{b});
    EXPECT_EQ(m.bodies[b].state.position, s.position);
    EXPECT_EQ(m.bodies[b].state.theta, s.theta);
    EXPECT_EQ(m.bodies[b].state.velocity, s.velocity);
    EXPECT_EQ(m.bodies[b].state.omega, s.omega);
  }
  for (std::size_t n = 0; n < out.size() - 3; ++n) {
    EXPECT_FALSE(rbsim::msgs::decode_body_states(std::span(out).first(n), m).ok()) << n;
  }
}

// The typed decoders of the other per-step messages read what the schema-driven decoder reads,
// value by value in field order, and refuse truncated bytes.
TEST(DecodeTyped, SpringStatesEnergyTermsAndPosesAgreeWithTheSchemaDecoder) {
  rbsim::Scene scene = spring_wind_scene();
  auto w = rbsim::World::create(scene.world);
  ASSERT_TRUE(w.ok());
  for (int i = 0; i < 17; ++i) w->step();
  const rbsim::msgs::Encoder encoder(scene);
  auto number = [](const Scalar& s) {
    switch (s.kind) {
      case Scalar::Kind::Float:
        return s.f;
      case Scalar::Kind::Int:
      case Scalar::Kind::Bool:
        return static_cast<double>(s.i);
      default:
        return static_cast<double>(s.u);
    }
  };
  // The schema decoder's numbers (strings skipped) against the typed message's, flattened.
  auto expect_same = [&](TopicId id, const rbsim::msgs::Bytes& cdr, const std::vector<double>& typed) {
    std::vector<Scalar> scalars;
    ASSERT_TRUE(decoder_for(id).decode(cdr, scalars).ok());
    std::vector<double> want;
    for (const Scalar& s : scalars) {
      if (s.kind != Scalar::Kind::String) want.push_back(number(s));
    }
    EXPECT_EQ(typed, want) << rbsim::msgs::topic(id).suffix;
  };
  rbsim::msgs::Bytes out;
  encoder.spring_states(w.value(), out);
  rbsim::msgs::SpringStatesMessage springs;
  ASSERT_TRUE(rbsim::msgs::decode_spring_states(out, springs).ok());
  EXPECT_EQ(springs.step, 17u);
  ASSERT_FALSE(springs.springs.empty());
  {
    std::vector<double> v = {double(springs.stamp.sec), double(springs.stamp.nanosec), double(springs.step),
                             double(springs.springs.size())};
    for (const auto& x : springs.springs) {
      v.insert(v.end(), {double(x.id), x.end_i.x(), x.end_i.y(), x.end_j.x(), x.end_j.y(), x.length,
                         x.rest_length, x.potential});
    }
    expect_same(TopicId::SpringStates, out, v);
  }
  for (std::size_t n = 0; n < out.size() - 3; ++n)
    EXPECT_FALSE(rbsim::msgs::decode_spring_states(std::span(out).first(n), springs).ok()) << n;

  encoder.energy(w.value(), out);
  rbsim::msgs::EnergyTermsMessage energy;
  ASSERT_TRUE(rbsim::msgs::decode_energy_terms(out, energy).ok());
  EXPECT_DOUBLE_EQ(energy.total, w->energy().total());  // summed in another order than Energy::total()
  {
    std::vector<double> v = {double(energy.stamp.sec), double(energy.stamp.nanosec), double(energy.step),
                             double(energy.bodies.size())};
    for (const auto& b : energy.bodies)
      v.insert(v.end(),
               {double(b.id), b.momentum.x(), b.momentum.y(), b.l_point, b.l_spin, b.t_point, b.t_spin});
    v.push_back(double(energy.forces.size()));
    for (const auto& f : energy.forces) v.insert(v.end(), {double(f.kind), double(f.index), f.potential});
    v.insert(v.end(), {energy.momentum.x(), energy.momentum.y(), energy.angular_momentum, energy.potential,
                       energy.kinetic_point, energy.kinetic_spin, energy.total, energy.potential_gravity,
                       energy.potential_spring});
    expect_same(TopicId::Energy, out, v);
  }
  for (std::size_t n = 0; n < out.size() - 3; ++n)
    EXPECT_FALSE(rbsim::msgs::decode_energy_terms(std::span(out).first(n), energy).ok()) << n;

  encoder.poses(w.value(), out);
  rbsim::msgs::PosesMessage poses;
  ASSERT_TRUE(rbsim::msgs::decode_poses(out, poses).ok());
  ASSERT_EQ(poses.poses.size(), 3u);
  {
    std::vector<double> v = {double(poses.stamp.sec), double(poses.stamp.nanosec),
                             double(poses.poses.size())};
    for (const auto& p : poses.poses) v.insert(v.end(), {p.x, p.y, p.z, p.qx, p.qy, p.qz, p.qw});
    expect_same(TopicId::Poses, out, v);
  }
  for (std::size_t n = 0; n < out.size() - 3; ++n)
    EXPECT_FALSE(rbsim::msgs::decode_poses(std::span(out).first(n), poses).ok()) << n;
}

// Every per-step message names its simulated time (what the recorder counts gaps by); the scene
// description and bytes too short to hold a stamp give none.
TEST(DecodeStamp, GivesTheSimulatedTimeOfEveryPerStepTopic) {
  rbsim::Scene scene = spring_wind_scene();
  auto w = rbsim::World::create(scene.world);
  ASSERT_TRUE(w.ok());
  for (int i = 0; i < 1234; ++i) w->step();
  const rbsim::msgs::Time want = rbsim::msgs::sim_time(w.value());
  ASSERT_GT(want.sec, 0);
  ASSERT_GT(want.nanosec, 0u);
  const rbsim::msgs::Encoder encoder(scene);
  rbsim::msgs::Bytes out;
  for (const rbsim::msgs::TopicSpec& spec : rbsim::msgs::topics()) {
    if (spec.event) continue;  // not encoded from a World: below
    encoder.encode(spec.id, w.value(), out);
    const auto got = rbsim::msgs::decode_stamp(spec.id, out);
    if (spec.id == TopicId::SceneDescription) {
      EXPECT_FALSE(got.has_value());
      continue;
    }
    ASSERT_TRUE(got.has_value()) << spec.suffix;
    EXPECT_EQ(got->sec, want.sec) << spec.suffix;
    EXPECT_EQ(got->nanosec, want.nanosec) << spec.suffix;
    const std::size_t header =
        spec.id == TopicId::Markers || spec.id == TopicId::Tf ? 16 : 12;  // encapsulation, [length,] stamp
    EXPECT_FALSE(rbsim::msgs::decode_stamp(spec.id, std::span(out).first(header - 1)).has_value())
        << spec.suffix;
  }
  // An empty MarkerArray carries no stamp.
  const std::byte empty[] = {std::byte{0}, std::byte{1}, std::byte{0}, std::byte{0},
                             std::byte{0}, std::byte{0}, std::byte{0}, std::byte{0}};
  EXPECT_FALSE(rbsim::msgs::decode_stamp(TopicId::Markers, empty).has_value());
  // A command carries the stamp of the step it applied at, after its seq and step.
  rbsim::msgs::CommandMessage c;
  c.seq = 9;
  c.step = 1234;
  c.stamp = want;
  rbsim::msgs::encode(c, out);
  const auto got = rbsim::msgs::decode_stamp(TopicId::Commands, out);
  ASSERT_TRUE(got.has_value());
  EXPECT_EQ(got->sec, want.sec);
  EXPECT_EQ(got->nanosec, want.nanosec);
  EXPECT_FALSE(rbsim::msgs::decode_stamp(TopicId::Commands, std::span(out).first(23)).has_value());
}

// The one step rule: the step field where a type has one (even against its stamp), else
// round(stamp / dt) (the scene description's: the step it describes the world at); nothing
// without either, or with a dt that cannot divide.
TEST(MessageStep, UsesTheStepFieldElseTheStampOverDt) {
  rbsim::Scene scene = spring_wind_scene();
  auto w = rbsim::World::create(scene.world);
  ASSERT_TRUE(w.ok());
  for (int i = 0; i < 1234; ++i) w->step();
  const double dt = scene.world.dt;
  const rbsim::msgs::Encoder encoder(scene);
  rbsim::msgs::Bytes out;
  for (const rbsim::msgs::TopicSpec& spec : rbsim::msgs::topics()) {
    if (spec.event) continue;  // not encoded from a World: below
    encoder.encode(spec.id, w.value(), out);
    const auto step = rbsim::msgs::message_step(spec.id, out, dt);  // the scene description's too
    ASSERT_TRUE(step.has_value()) << spec.suffix;
    EXPECT_EQ(*step, 1234u) << spec.suffix;
    const bool has_field =
        spec.id == TopicId::BodyStates || spec.id == TopicId::SpringStates || spec.id == TopicId::Energy;
    // A dt that cannot divide: only the types that carry their step still have one.
    EXPECT_EQ(rbsim::msgs::message_step(spec.id, out, 0.0).has_value(), has_field) << spec.suffix;
    EXPECT_EQ(rbsim::msgs::message_step(spec.id, out, std::nan("")).has_value(), has_field) << spec.suffix;
    // Twice the dt halves a stamp's step, never a step field's.
    EXPECT_EQ(rbsim::msgs::message_step(spec.id, out, 2 * dt), has_field ? 1234u : 617u) << spec.suffix;
    EXPECT_FALSE(rbsim::msgs::message_step(spec.id, std::span(out).first(8), dt).has_value()) << spec.suffix;
  }
  const std::byte empty[] = {std::byte{0}, std::byte{1}, std::byte{0}, std::byte{0},
                             std::byte{0}, std::byte{0}, std::byte{0}, std::byte{0}};
  EXPECT_FALSE(rbsim::msgs::message_step(TopicId::Markers, empty, dt).has_value());
  // A command's step is its step field, whatever its stamp says.
  rbsim::msgs::CommandMessage c;
  c.seq = 9;
  c.step = 77;
  c.stamp = rbsim::msgs::sim_time(w.value());
  rbsim::msgs::encode(c, out);
  EXPECT_EQ(rbsim::msgs::message_step(TopicId::Commands, out, dt), 77u);
  EXPECT_EQ(rbsim::msgs::message_step(TopicId::Commands, out, 0.0), 77u);
  EXPECT_FALSE(rbsim::msgs::message_step(TopicId::Commands, std::span(out).first(15), dt).has_value());
}

// Metadata is what a scene description says about itself, not its physics: every field of the
// schema is one or the other, and rbsim check reports only the metadata apart.
TEST(IsSceneMetadata, TellsTheDescriptiveFieldsFromThePhysics) {
  for (const char* meta : {"name", "description", "has_viewport", "viewport_cx", "viewport_cy",
                           "viewport_size", "background.r", "background.a"})
    EXPECT_TRUE(rbsim::msgs::is_scene_metadata(meta)) << meta;
  for (const char* physics : {"dt", "duration", "step_count", "integrator", "bodies[].mass", "springs[].k",
                              "gravity[].gx", "header.stamp.sec", "names", "background"})
    EXPECT_FALSE(rbsim::msgs::is_scene_metadata(physics)) << physics;
}

}  // namespace
