// type_description_interfaces (rbsim/type_description.hpp: the structs and their codecs) and the
// structured type description rbsim/type_hash.hpp builds: round trips, a byte layout derived by
// hand from the CDR rules, malformed input, the description of known types checked field by field
// and through its hash against published values (never computed here), rosidl's spelling of
// default values and the type sources rosidl_generator_c embeds.
#include "rbsim/type_description.hpp"

#include <gtest/gtest.h>

#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "rbsim/type_hash.hpp"

namespace rbsim::msgs {
namespace {

Bytes bytes(std::initializer_list<int> v) {
  Bytes out;
  for (int b : v) out.push_back(static_cast<std::byte>(b));
  return out;
}

// A definition source over literal texts, the shipped definitions behind them.
DefinitionSource over_shipped(std::map<std::string, std::string, std::less<>> defs) {
  auto shared = std::make_shared<std::map<std::string, std::string, std::less<>>>(std::move(defs));
  return [shared](std::string_view type) -> std::optional<std::string_view> {
    if (const auto it = shared->find(type); it != shared->end()) return std::string_view(it->second);
    return shipped_definition(type);
  };
}

// A response with every field set, so a field read from the wrong place shows.
GetTypeDescriptionResponse full_response() {
  GetTypeDescriptionResponse r;
  r.successful = true;
  r.failure_reason = "none";
  r.type_description.type_description = {
      "pkg/msg/A",
      {Field{"x", FieldType{11, 0, 0, ""}, "1.5"}, Field{"b", FieldType{1 + 144, 0, 0, "pkg/msg/B"}, ""},
       Field{"s", FieldType{21 + 48, 3, 10, ""}, "('a', 'b', 'c')"}}};
  r.type_description.referenced_type_descriptions = {{"pkg/msg/B", {Field{"u", FieldType{9, 0, 0, ""}, ""}}}};
  r.type_sources = {TypeSource{"pkg/msg/A", "msg", "float64 x 1.5\nB[] b"},
                    TypeSource{"pkg/msg/B", "implicit", ""}};
  r.extra_information = {KeyValue{"k", "v"}};
  return r;
}

template <class T>
T round_trip(const T& in) {
  Bytes cdr;
  encode(in, cdr);
  T out;
  EXPECT_TRUE(decode(cdr, out).ok());
  return out;
}

TEST(TypeDescriptionCodec, EveryTypeRoundTrips) {
  const GetTypeDescriptionResponse res = full_response();
  EXPECT_EQ(round_trip(res), res);
  EXPECT_EQ(round_trip(res.type_description), res.type_description);
  EXPECT_EQ(round_trip(res.type_sources[0]), res.type_sources[0]);
  const GetTypeDescriptionRequest req{"std_msgs/msg/String", "RIHS01_00", false};
  EXPECT_EQ(round_trip(req), req);
  EXPECT_EQ(round_trip(GetTypeDescriptionResponse{}), GetTypeDescriptionResponse{});
}

// string type_name "a", string type_hash "", bool include_type_sources: u32 length + text + NUL
// each, then one byte; the message padded to 4 with the pad count in the header's last byte.
TEST(TypeDescriptionCodec, RequestLayoutIsPlainCdr) {
  Bytes cdr;
  encode(GetTypeDescriptionRequest{"a", "", true}, cdr);
  EXPECT_EQ(cdr, bytes({0, 1, 0, 2, 2, 0, 0, 0, 'a', 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0}));
}

TEST(TypeDescriptionCodec, EveryTruncationIsAnErrorNamingTheType) {
  Bytes cdr;
  encode(full_response(), cdr);
  // The last bytes may be padding only: cut where the last value ends.
  for (std::size_t n = 0; n + 4 < cdr.size(); ++n) {
    GetTypeDescriptionResponse out;
    const Status st = decode(std::span<const std::byte>(cdr.data(), n), out);
    ASSERT_FALSE(st.ok()) << n;
    EXPECT_NE(st.error().message.find("type_description_interfaces/srv/GetTypeDescription response"),
              std::string::npos)
        << st.error().message;
  }
}

TEST(TypeDescriptionCodec, NameOverItsBoundOrHugeLengthIsRefused) {
  GetTypeDescriptionResponse res;
  res.type_description.type_description.type_name = std::string(256, 'a');  // string<=255
  Bytes cdr;
  encode(res, cdr);
  GetTypeDescriptionResponse out;
  EXPECT_FALSE(decode(cdr, out).ok());
  res.type_description.type_description.type_name = std::string(255, 'a');
  encode(res, cdr);
  EXPECT_TRUE(decode(cdr, out).ok());

  // A sequence length of 2^32 - 1 fields in a short message fails before allocating.
  encode(TypeDescription{}, cdr);
  // type_name "" (4 + 1 bytes), padding to 8, then the fields' length.
  cdr[4 + 8] = cdr[4 + 9] = cdr[4 + 10] = cdr[4 + 11] = std::byte{0xff};
  TypeDescription td;
  EXPECT_FALSE(decode(cdr, td).ok());
}

TEST(TypeDescriptionCodec, RandomBytesNeverCrash) {
  std::mt19937 rng(37);
  Bytes good;
  encode(full_response(), good);
  for (int i = 0; i < 2000; ++i) {
    Bytes b = good;
    for (int k = 0; k < 4; ++k) b[4 + rng() % (b.size() - 4)] = static_cast<std::byte>(rng());
    GetTypeDescriptionResponse out;
    (void)decode(b, out);
  }
}

// --- The structured description --------------------------------------------------------------

// The described fields of std_msgs/msg/Header, and through its hash the whole description:
// RIHS01_f49f... is the published hash (type_hash_test.cpp names where from).
TEST(TypeDescription, OfHeaderIsItsFieldsAndTime) {
  const auto d = type_description("std_msgs/msg/Header");
  ASSERT_TRUE(d.ok()) << d.error().message;
  const IndividualTypeDescription& root = d.value().type_description;
  EXPECT_EQ(root.type_name, "std_msgs/msg/Header");
  ASSERT_EQ(root.fields.size(), 2u);
  EXPECT_EQ(root.fields[0], (Field{"stamp", FieldType{1, 0, 0, "builtin_interfaces/msg/Time"}, ""}));
  EXPECT_EQ(root.fields[1], (Field{"frame_id", FieldType{17, 0, 0, ""}, ""}));
  ASSERT_EQ(d.value().referenced_type_descriptions.size(), 1u);
  const IndividualTypeDescription& time = d.value().referenced_type_descriptions[0];
  EXPECT_EQ(time.type_name, "builtin_interfaces/msg/Time");
  ASSERT_EQ(time.fields.size(), 2u);
  EXPECT_EQ(time.fields[0].type.type_id, 6);  // int32 sec
  EXPECT_EQ(time.fields[1].type.type_id, 7);  // uint32 nanosec
  EXPECT_EQ(type_hash(d.value()).value(),
            "RIHS01_f49fb3ae2cf070f793645ff749683ac6b06203e41c891e17701b1cb597ce6a01");
}

// The service's hash as others pin Jazzy's (a Zenoh ROS 2 client, ros-z, serves
// ~/get_type_description under it; rosbags computes the same, rihs01_rosbags.txt).
TEST(TypeDescription, OfGetTypeDescriptionHashesAsPublished) {
  const auto d = type_description("type_description_interfaces/srv/GetTypeDescription");
  ASSERT_TRUE(d.ok()) << d.error().message;
  EXPECT_EQ(type_hash(d.value()).value(),
            "RIHS01_69b9c19c1021405984cc60dbbb1edceb147a6538b411d812ba6afabeed962cd5");
}

// The hash is the description's: for every shipped type, hashing the structured description
// gives what type_hash(type) gives (checked against rosbags by type_hash_test.cpp), and its JSON is
// type_description_json's.
TEST(TypeDescription, HashOfTheDescriptionIsTheTypeHash) {
  for (const std::string_view type : definition_types()) {
    const auto d = type_description(type);
    ASSERT_TRUE(d.ok()) << type << ": " << d.error().message;
    EXPECT_EQ(type_hash(d.value()).value(), type_hash(type).value()) << type;
    EXPECT_EQ(type_description_json(d.value()), type_description_json(type, shipped_definition).value());
  }
  // A type rosidl derives from a service, which has no definition of its own.
  const auto event = type_description("std_srvs/srv/Trigger_Event");
  ASSERT_TRUE(event.ok());
  EXPECT_EQ(type_hash(event.value()).value(), type_hash("std_srvs/srv/Trigger_Event").value());
}

// rosidl's spelling of .msg defaults: str() of the Python value rosidl_parser reads back
// (rosidl_adapter parses the .msg value, writes it as an IDL @default annotation).
TEST(TypeDescription, DefaultValuesAreRosidlsSpelling) {
  const auto q = type_description("geometry_msgs/msg/Quaternion");
  ASSERT_TRUE(q.ok());
  std::vector<std::string> defaults;
  for (const Field& f : q.value().type_description.fields) defaults.push_back(f.default_value);
  EXPECT_EQ(defaults, (std::vector<std::string>{"0.0", "0.0", "0.0", "1.0"}));  // float64 x 0 ... w 1

  const auto req = type_description("type_description_interfaces/srv/GetTypeDescription_Request");
  ASSERT_TRUE(req.ok());
  EXPECT_EQ(req.value().type_description.fields.at(2).default_value, "True");  // bool ... true
  const auto desc = type_description("rcl_interfaces/msg/ParameterDescriptor");
  ASSERT_TRUE(desc.ok());
  for (const Field& f : desc.value().type_description.fields) {
    EXPECT_EQ(f.default_value, f.name == "read_only" || f.name == "dynamic_typing" ? "False" : "") << f.name;
  }

  const auto d = type_description(
      "t/msg/D", over_shipped({{"t/msg/D",
                                "float32 a 1e-5\nint8 b -0x10\nbool c 1\nstring d \"hi there\" # note\n"
                                "float64[2] e [0, 1.5]\nint32[<=3] f [7]\nstring[] g ['x', 'y']\n"
                                "float64 h 1e16\nfloat64 i 123456789\nuint8 j\nfloat64 k -0.0\n"
                                "uint64 l 18446744073709551615\n"}}));
  ASSERT_TRUE(d.ok()) << d.error().message;
  defaults.clear();
  for (const Field& f : d.value().type_description.fields) defaults.push_back(f.default_value);
  EXPECT_EQ(defaults,
            (std::vector<std::string>{"1e-05", "-16", "True", "hi there", "(0.0, 1.5)", "(7,)", "('x', 'y')",
                                      "1e+16", "123456789.0", "", "-0.0", "18446744073709551615"}));
  // Defaults are left out of the hash.
  const auto plain =
      type_description("t/msg/D", over_shipped({{"t/msg/D",
                                                 "float32 a\nint8 b\nbool c\nstring d\n"
                                                 "float64[2] e\nint32[<=3] f\nstring[] g\n"
                                                 "float64 h\nfloat64 i\nuint8 j\nfloat64 k\nuint64 l\n"}}));
  ASSERT_TRUE(plain.ok());
  EXPECT_EQ(type_hash(d.value()).value(), type_hash(plain.value()).value());
  EXPECT_NE(d.value(), plain.value());
}

TEST(TypeDescription, BadDefaultValueIsAnErrorNamingTheField) {
  for (const char* text : {"bool b maybe\n", "int32 i 1.5\n", "float64 f x\n", "float64[2] a 1, 2\n"}) {
    const auto d = type_description("t/msg/Bad", over_shipped({{"t/msg/Bad", text}}));
    ASSERT_FALSE(d.ok()) << text;
    EXPECT_NE(d.error().message.find("t/msg/Bad: field"), std::string::npos) << d.error().message;
  }
}

// rosidl_generator_c's get_type_description_sources: the type first, then its referenced types in
// the description's order; a definition file's kind and text (final newline dropped), "implicit"
// for what rosidl derives from a service.
TEST(TypeSources, AreTheDefinitionTextsAndImplicitForDerivedTypes) {
  const std::string service = "type_description_interfaces/srv/GetTypeDescription";
  const auto d = type_description(service);
  ASSERT_TRUE(d.ok());
  const std::vector<TypeSource> sources = type_sources(d.value(), shipped_definition);
  ASSERT_EQ(sources.size(), 1 + d.value().referenced_type_descriptions.size());
  std::string text(*shipped_definition(service));
  ASSERT_EQ(text.back(), '\n');
  text.pop_back();
  EXPECT_EQ(sources[0], (TypeSource{service, "srv", text}));
  std::map<std::string, TypeSource> by_name;
  for (std::size_t i = 1; i < sources.size(); ++i) {
    EXPECT_EQ(sources[i].type_name, d.value().referenced_type_descriptions[i - 1].type_name);
    by_name[sources[i].type_name] = sources[i];
  }
  for (const char* derived : {"_Request", "_Response", "_Event"}) {
    EXPECT_EQ(by_name.at(service + derived), (TypeSource{service + derived, "implicit", ""}));
  }
  const TypeSource& field = by_name.at("type_description_interfaces/msg/Field");
  EXPECT_EQ(field.encoding, "msg");
  EXPECT_EQ(field.raw_file_contents + "\n", *shipped_definition("type_description_interfaces/msg/Field"));
  EXPECT_EQ(by_name.at("service_msgs/msg/ServiceEventInfo").encoding, "msg");
}

TEST(TypeSources, LinesAreJoinedByNewlinesAsPythonSplitsThem) {
  const auto source = over_shipped({{"t/msg/Crlf", "int32 a\r\nint32 b\n\n"}});
  const auto d = type_description("t/msg/Crlf", source);
  ASSERT_TRUE(d.ok()) << d.error().message;
  EXPECT_EQ(type_sources(d.value(), source).at(0).raw_file_contents, "int32 a\nint32 b\n");
}

}  // namespace
}  // namespace rbsim::msgs
