// REP 2011 type hashes (rbsim/type_hash.hpp) against hashes published by others. Definitions rbsim
// does not ship are test data (test/msgs/data, upstream files byte for byte; its README names
// where each comes from); the rest are the shipped ones. Every expected value below is copied from
// the source named beside it, never computed here.
#include "rbsim/type_hash.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>

#include "rbsim/msgs.hpp"

namespace {

using rbsim::msgs::DefinitionSource;

// test/msgs/data/<pkg>/<msg|srv>/<Name>.<msg|srv>, else the shipped definition.
std::optional<std::string_view> test_definition(std::string_view type) {
  static std::map<std::string, std::string, std::less<>> loaded;
  if (const auto it = loaded.find(type); it != loaded.end()) return it->second;
  const std::string kind = std::string(type).find("/srv/") != std::string::npos ? ".srv" : ".msg";
  const std::filesystem::path path = std::filesystem::path(RBSIM_TEST_MSG_DATA) / (std::string(type) + kind);
  std::ifstream in(path, std::ios::binary);
  if (!in) return rbsim::msgs::shipped_definition(type);
  std::ostringstream text;
  text << in.rdbuf();
  return loaded.emplace(std::string(type), text.str()).first->second;
}

std::string hash_of(std::string_view type) {
  auto h = rbsim::msgs::type_hash(type, test_definition);
  EXPECT_TRUE(h.ok()) << type << ": " << (h.ok() ? "" : h.error().message);
  return h.ok() ? h.value() : std::string();
}

// A definition source over literal texts, for the error cases.
DefinitionSource texts(std::map<std::string, std::string, std::less<>> defs) {
  auto shared = std::make_shared<std::map<std::string, std::string, std::less<>>>(std::move(defs));
  return [shared](std::string_view type) -> std::optional<std::string_view> {
    const auto it = shared->find(type);
    if (it == shared->end()) return std::nullopt;
    return std::string_view(it->second);
  };
}

// --- Published values ---------------------------------------------------------------------------

// The three of issue 22 (also in RosLibRust/roslibrust roslibrust_codegen/assets/String.json, a
// rosidl_generator_type_description output, for String; the 2lian/ros2-pyterfaces tests for Header).
TEST(TypeHash, StdMsgsStringHeaderAndNavMsgsOdometryMatchPublished) {
  EXPECT_EQ(hash_of("std_msgs/msg/String"),
            "RIHS01_df668c740482bbd48fb39d76a70dfd4bd59db1288021743503259e948f6b1a18");
  EXPECT_EQ(hash_of("std_msgs/msg/Header"),
            "RIHS01_f49fb3ae2cf070f793645ff749683ac6b06203e41c891e17701b1cb597ce6a01");
  EXPECT_EQ(hash_of("nav_msgs/msg/Odometry"),
            "RIHS01_3cc97dc7fb7502f8714462c526d369e35b603cfc34d946e3f2eda2766dfec6e0");
}

// rosidl's generated JSON for example_interfaces/srv/AddTwoInts (RosLibRust/roslibrust
// roslibrust_codegen/assets/AddTwoInts.json, "type_hashes"): the service, its three messages and the
// types they use. The _Event hash is also what rosbag2 (jazzy) recorded for /add_two_ints/_service_event
// in rosbag2_cpp/test/rosbag2_cpp/bags/topics_and_services.mcap.
TEST(TypeHash, ServiceAndItsMessagesMatchRosidlOutput) {
  EXPECT_EQ(hash_of("example_interfaces/srv/AddTwoInts"),
            "RIHS01_e118de6bf5eeb66a2491b5bda11202e7b68f198d6f67922cf30364858239c81a");
  EXPECT_EQ(hash_of("example_interfaces/srv/AddTwoInts_Request"),
            "RIHS01_000c5fd92d6b2e1a05949348f584d6d652adea1e92d691792011ac2273508302");
  EXPECT_EQ(hash_of("example_interfaces/srv/AddTwoInts_Response"),
            "RIHS01_de5c030d4af33cba2749310b249737b631594703f9300495f48bffb2b44dcc2f");
  EXPECT_EQ(hash_of("example_interfaces/srv/AddTwoInts_Event"),
            "RIHS01_32c1d140259c71e5c355115942bcb31df98b4330e4d906b1b75ccb1c9b3ce6c8");
  EXPECT_EQ(hash_of("builtin_interfaces/msg/Time"),
            "RIHS01_b106235e25a4c5ed35098aa0a61a3ee9c9b18d197f398b0e4206cea9acf9c197");
  EXPECT_EQ(hash_of("service_msgs/msg/ServiceEventInfo"),
            "RIHS01_41bcbbe07a75c9b52bc96bfd5c24d7f0fc0a08c0cb7921b3373c5732345a6f45");
}

// rosbag2 (jazzy) test bags: the type_description_hash of /rosout and /parameter_events in
// rosbag2_cpp/test/rosbag2_cpp/bags/topics_and_services.mcap (Log.msg and ParameterEvent.msg and
// what they use are unchanged from then to Jazzy); both from the shipped definitions.
TEST(TypeHash, RclInterfacesLogAndParameterEventMatchRosbag2Bags) {
  EXPECT_EQ(hash_of("rcl_interfaces/msg/Log"),
            "RIHS01_e28ce254ca8abc06abf92773b74602cdbf116ed34fbaf294fb9f81da9f318eac");
  EXPECT_EQ(hash_of("rcl_interfaces/msg/ParameterEvent"),
            "RIHS01_043e627780fcad87a22d225bc2a037361dba713fca6a6b9f4b869a5aa0393204");
}

// rosbag2 (jazzy) rosbag2_tests/resources/mcap/bag_with_topics_and_service_events/metadata.yaml:
// bounded strings with default values (Strings), a service event of every primitive (BasicTypes),
// and WriteSplitEvent as it was when the bag was recorded. The same WriteSplitEvent hash is in
// rosbag2_cpp/test/rosbag2_cpp/bags/topics_and_services.mcap.
TEST(TypeHash, BoundedStringsDefaultsAndEventsMatchRosbag2Metadata) {
  EXPECT_EQ(hash_of("test_msgs/msg/Strings"),
            "RIHS01_eee55533636293ac7c94c62432eedb5777eb849847d2a17b4dcead8c4a20ab32");
  EXPECT_EQ(hash_of("test_msgs/srv/BasicTypes_Event"),
            "RIHS01_5b9988a4805a06ae22dff12903a774ccda710e9514926b826ffc884e3a9a982e");
  EXPECT_EQ(hash_of("rosbag2_interfaces/msg/WriteSplitEvent"),
            "RIHS01_5ef58f7106a5cff8f5a794028c18117ee21015850ddcc567df449f41932960f8");
}

// RosLibRust/roslibrust: roslibrust_codegen/assets/{ColorRGBA,MultiArrayLayout}.json (rosidl
// output) and roslibrust_test/tests/ros2_codegen_tests.rs (ros2_hash_checks): an empty message
// (rosidl's structure_needs_at_least_one_member), fixed arrays and a nested type (CameraInfo), an
// empty and a small service. ColorRGBA is the shipped definition.
TEST(TypeHash, EmptyMessagesArraysAndSmallServicesMatchRoslibrust) {
  EXPECT_EQ(hash_of("std_msgs/msg/ColorRGBA"),
            "RIHS01_77a7a5b9ae477306097665106e0413ba74440245b1f3d0c6d6405fe5c7813fe8");
  EXPECT_EQ(hash_of("std_msgs/msg/MultiArrayLayout"),
            "RIHS01_4c66e6f78e740ac103a94cf63259f968e48c617e7699e829b63c21a5cb50dac6");
  EXPECT_EQ(hash_of("std_msgs/msg/MultiArrayDimension"),
            "RIHS01_5e773a60a4c7fc8a54985f307c7837aa2994252a126c301957a24e31282c9cbe");
  EXPECT_EQ(hash_of("std_msgs/msg/Empty"),
            "RIHS01_20b625256f32d5dbc0d04fee44f43c41e51c70d3502f84b4a08e7a9c26a96312");
  EXPECT_EQ(hash_of("sensor_msgs/msg/CameraInfo"),
            "RIHS01_b3dfd68ff46c9d56c80fd3bd4ed22c7a4ddce8c8348f2f59c299e73118e7e275");
  EXPECT_EQ(hash_of("std_srvs/srv/SetBool"),
            "RIHS01_abe9e4bb6b41b40e6789712c00ec8871923e089af3f667a79992a428cff2da0a");
  EXPECT_EQ(hash_of("std_srvs/srv/Empty"),
            "RIHS01_5888399dedec5ccc85ea6451949fd2c9f97bfdf963f9a588821639fcd31b5d19");
}

// The hashed text itself, in the form rosidl_generator_type_description's calculate_type_hash
// writes (json.dumps, separators ", " and ": ", default_value removed).
TEST(TypeDescriptionJson, IsRosidlsHashedForm) {
  auto json = rbsim::msgs::type_description_json("builtin_interfaces/msg/Time", test_definition);
  ASSERT_TRUE(json.ok()) << json.error().message;
  EXPECT_EQ(json.value(),
            "{\"type_description\": {\"type_name\": \"builtin_interfaces/msg/Time\", \"fields\": ["
            "{\"name\": \"sec\", \"type\": {\"type_id\": 6, \"capacity\": 0, \"string_capacity\": 0, "
            "\"nested_type_name\": \"\"}}, "
            "{\"name\": \"nanosec\", \"type\": {\"type_id\": 7, \"capacity\": 0, \"string_capacity\": 0, "
            "\"nested_type_name\": \"\"}}]}, \"referenced_type_descriptions\": []}");
}

// --- The shipped definitions ----------------------------------------------------------------

// Jazzy's Gid is char[16] (Humble's char[24]): a uint8 array (rosidl maps .msg char to uint8) of 16.
TEST(TypeDescriptionJson, ShippedGidIsJazzys16ByteArray) {
  auto json = rbsim::msgs::type_description_json("rmw_dds_common/msg/Gid", rbsim::msgs::shipped_definition);
  ASSERT_TRUE(json.ok()) << json.error().message;
  EXPECT_NE(json.value().find("{\"name\": \"data\", \"type\": {\"type_id\": 51, \"capacity\": 16, "),
            std::string::npos)
      << json.value();
}

TEST(TypeHash, EveryShippedTypeAndServiceHashes) {
  std::vector<std::string> types;
  for (std::string_view t : rbsim::msgs::definition_types()) types.emplace_back(t);
  for (std::string_view s : rbsim::msgs::service_types()) {
    for (const char* suffix : {"", "_Request", "_Response", "_Event"})
      types.push_back(std::string(s) + suffix);
  }
  EXPECT_GE(rbsim::msgs::service_types().size(), 9u);  // rcl_interfaces' six, Trigger, Step, ApplyImpulse
  for (const std::string& t : types) {
    SCOPED_TRACE(t);
    auto cached = rbsim::msgs::type_hash(t);
    ASSERT_TRUE(cached.ok()) << cached.error().message;
    EXPECT_EQ(cached.value().size(), 7u + 64u);
    EXPECT_TRUE(cached.value().starts_with("RIHS01_"));
    // The cache serves what the uncached computation gives, the second time too.
    EXPECT_EQ(cached.value(), rbsim::msgs::type_hash(t, rbsim::msgs::shipped_definition).value());
    EXPECT_EQ(cached.value(), rbsim::msgs::type_hash(t).value());
  }
}

// rmw_cyclonedds_cpp (jazzy) rmw_node.cpp, create_cdds_client/create_cdds_service: the request
// endpoints carry the _Request message's hash, the reply endpoints the _Response message's.
TEST(ServiceEndpointTypeHashes, AreTheRequestAndResponseMessageHashes) {
  for (const char* service :
       {"std_srvs/srv/Trigger", "rbsim_msgs/srv/Step", "rcl_interfaces/srv/GetParameters"}) {
    SCOPED_TRACE(service);
    auto hashes = rbsim::msgs::service_endpoint_type_hashes(service);
    ASSERT_TRUE(hashes.ok()) << hashes.error().message;
    EXPECT_EQ(hashes.value().request, rbsim::msgs::type_hash(std::string(service) + "_Request").value());
    EXPECT_EQ(hashes.value().reply, rbsim::msgs::type_hash(std::string(service) + "_Response").value());
    EXPECT_NE(hashes.value().request, hashes.value().reply);
    EXPECT_NE(hashes.value().request, rbsim::msgs::type_hash(service).value());
  }
  EXPECT_FALSE(rbsim::msgs::service_endpoint_type_hashes("std_srvs/srv/Nope").ok());
  EXPECT_FALSE(rbsim::msgs::service_endpoint_type_hashes("std_msgs/msg/Header").ok());
}

// rmw_dds_common's encode_type_hash_for_user_data_qos.
TEST(TypehashUserData, IsRmwDdsCommonsEntry) {
  EXPECT_EQ(rbsim::msgs::typehash_user_data("RIHS01_00ff"), "typehash=RIHS01_00ff;");
}

// --- Bad input ---------------------------------------------------------------------------------

TEST(TypeHash, UnknownTypeIsAnError) {
  auto h = rbsim::msgs::type_hash("nope_msgs/msg/Nope");
  ASSERT_FALSE(h.ok());
  EXPECT_NE(h.error().message.find("nope_msgs/msg/Nope"), std::string::npos) << h.error().message;
  for (const char* bad : {"", "std_msgs", "std_msgs/msg/", "/msg/Header", "a/b/c/d", "std_msgs/action/X",
                          "std_msgs/msg/He der", "std_srvs/srv/_Request"}) {
    SCOPED_TRACE(bad);
    auto r = rbsim::msgs::type_hash(bad);
    ASSERT_FALSE(r.ok());
    EXPECT_FALSE(r.error().message.empty());
  }
}

TEST(TypeHash, MissingDependencyNamesItAndWhoNeedsIt) {
  auto h = rbsim::msgs::type_hash(
      "a_msgs/msg/A", texts({{"a_msgs/msg/A", "B b\n"}, {"a_msgs/msg/B", "other_msgs/C c # gone\n"}}));
  ASSERT_FALSE(h.ok());
  EXPECT_NE(h.error().message.find("no definition for other_msgs/msg/C"), std::string::npos)
      << h.error().message;
  EXPECT_NE(h.error().message.find("referenced by a_msgs/msg/B"), std::string::npos) << h.error().message;
  // A service's messages need the service_msgs/ServiceEventInfo of their event.
  auto event = rbsim::msgs::type_hash("a_msgs/srv/S_Event", texts({{"a_msgs/srv/S", "---\n"}}));
  ASSERT_FALSE(event.ok());
  EXPECT_NE(event.error().message.find("service_msgs/msg/ServiceEventInfo"), std::string::npos);
}

TEST(TypeHash, MalformedDefinitionsAreErrors) {
  const std::map<std::string, std::string, std::less<>> bad = {
      {"a_msgs/msg/Size", "int32[abc] x\n"},
      {"a_msgs/msg/Bound", "int32[<=] x\n"},
      {"a_msgs/msg/Str", "string<=x s\n"},
      {"a_msgs/msg/Nameless", "int32\n"},
      {"a_msgs/msg/Wide", "wstring w\n"},
      {"a_msgs/msg/Big", "int32[99999999999] x\n"},
      {"a_msgs/msg/Field", "int32 x-y\n"},
      {"a_msgs/srv/NoSep", "int32 a\n"},
      {"a_msgs/srv/TwoSeps", "int32 a\n---\n---\n"},
  };
  for (const auto& [type, text] : bad) {
    SCOPED_TRACE(type);
    std::string name = type;
    if (name.find("/srv/") != std::string::npos) name += "_Request";
    auto h = rbsim::msgs::type_hash(name, texts(bad));
    ASSERT_FALSE(h.ok());
    EXPECT_NE(h.error().message.find(type), std::string::npos) << h.error().message;
  }
}

// rosidl forbids a type that contains itself; a source that has one still gets an answer, not a
// loop or a crash. Random texts give a hash or an error, never a crash.
TEST(TypeHash, HostileDefinitionsNeverCrash) {
  EXPECT_TRUE(rbsim::msgs::type_hash("a_msgs/msg/A", texts({{"a_msgs/msg/A", "A[] children\n"}})).ok());
  std::mt19937 rng(22);
  const std::string alphabet = "abcz09_/[]<=#- \n\tAB";
  for (int i = 0; i < 2000; ++i) {
    std::string text;
    const int n = static_cast<int>(rng() % 40);
    for (int k = 0; k < n; ++k) text += alphabet[rng() % alphabet.size()];
    auto h = rbsim::msgs::type_hash("a_msgs/msg/R", texts({{"a_msgs/msg/R", text}}));
    if (h.ok()) {
      EXPECT_EQ(h.value().size(), 71u);
    }
  }
}

// --- Parsing the bounds the descriptions carry ----------------------------------------------

TEST(ParseMsgFields, ReadsSequenceAndStringBounds) {
  auto fields = rbsim::msgs::parse_msg_fields(
      "a_msgs/msg/A", "string<=256 name\nB[<=1] one\nint32[3] three\nstring<=22[] names\nbool flag false\n");
  ASSERT_TRUE(fields.ok()) << fields.error().message;
  const auto& f = fields.value();
  ASSERT_EQ(f.size(), 5u);
  EXPECT_EQ(f[0].string_capacity, 256u);
  EXPECT_EQ(f[0].array, rbsim::msgs::MsgField::Array::None);
  EXPECT_EQ(f[1].type, "a_msgs/msg/B");
  EXPECT_EQ(f[1].array, rbsim::msgs::MsgField::Array::Sequence);
  EXPECT_EQ(f[1].sequence_bound, 1u);
  EXPECT_EQ(f[2].array, rbsim::msgs::MsgField::Array::Fixed);
  EXPECT_EQ(f[2].fixed_size, 3u);
  EXPECT_EQ(f[3].string_capacity, 22u);
  EXPECT_EQ(f[3].sequence_bound, 0u);
  EXPECT_EQ(f[4].name, "flag");  // a default value is not a constant
}

}  // namespace
