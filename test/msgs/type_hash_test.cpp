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

// `defs` first, then the shipped definitions.
DefinitionSource over_shipped(std::map<std::string, std::string, std::less<>> defs) {
  auto own = texts(std::move(defs));
  return [own](std::string_view type) -> std::optional<std::string_view> {
    if (auto text = own(type)) return text;
    return rbsim::msgs::shipped_definition(type);
  };
}

// Every type rbsim ships and every type rosidl derives from them: each service's three messages,
// each action's twelve types (rbsim/type_hash.hpp).
std::vector<std::string> every_shipped_type() {
  std::vector<std::string> types;
  for (std::string_view t : rbsim::msgs::definition_types()) types.emplace_back(t);
  for (std::string_view s : rbsim::msgs::service_types()) {
    for (const char* suffix : {"", "_Request", "_Response", "_Event"})
      types.push_back(std::string(s) + suffix);
  }
  for (std::string_view a : rbsim::msgs::action_types()) {
    for (const char* suffix : {"", "_Goal", "_Result", "_Feedback", "_SendGoal", "_SendGoal_Request",
                               "_SendGoal_Response", "_SendGoal_Event", "_GetResult", "_GetResult_Request",
                               "_GetResult_Response", "_GetResult_Event", "_FeedbackMessage"}) {
      types.push_back(std::string(a) + suffix);
    }
  }
  return types;
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

// An action: rosidl_generator_type_description's output for robot_interfaces/action/NavigateToGoal
// (addinedu-ros-9th/ros-repo-4,
// install/robot_interfaces/share/robot_interfaces/action/NavigateToGoal.json, "type_hashes"): the
// action, the twelve types rosidl derives from it and the types they use (UUID, PoseStamped, Pose,
// ServiceEventInfo shipped). The .action text below is the fields of that file's
// type_description_msg, in order.
TEST(TypeHash, ActionAndItsDerivedTypesMatchRosidlOutput) {
  const DefinitionSource source = over_shipped(
      {{"robot_interfaces/action/NavigateToGoal",
        "int32 robot_id\ngeometry_msgs/PoseStamped target_pose\n---\nbool success\nstring message\n---\n"
        "geometry_msgs/PoseStamped current_pose\nstring current_status\n"}});
  const std::pair<const char*, const char*> published[] = {
      {"", "2eb7694618e36a43a93246acd54c7ffe2139e450666d199d3d1310f4efb7fada"},
      {"_Goal", "5041aaeb758a7265890c524170ff1cd7a27c2834263ce4d15f596a180fd0ef82"},
      {"_Result", "23ac9e803d1e96bf6b8be5e2781b2c6cb716478e9b81b646eedd6d92762cfba0"},
      {"_Feedback", "e2737d9d672216201de3f47806853c986927328690412d426251cf23dfa88345"},
      {"_FeedbackMessage", "604ebc5f2d6cdd380c610583db280686d7189a3f1aece06a34a569865195c524"},
      {"_SendGoal", "9bcc1d4c51059d0dabe099d2817c45e6e665f11c66fd14c5b3d21f1c794ea765"},
      {"_SendGoal_Request", "ed020abdab45ea31b1855fa5718e973fb01fcd836bc6194e3b4432dd7ac040e8"},
      {"_SendGoal_Response", "4c91df3d63ef0ca98b08a13cc9fe3953b74ac69a17bcf5a47bb0b31e913fe349"},
      {"_SendGoal_Event", "2b0d44152cd3b16458eea608caec4e35bcaea8979c4aada6e0a2c8e0bca76918"},
      {"_GetResult", "916442c7a15ce3904f0d0a236aa2c0d95fce3ec90d5383cfc5bf2fdb5d2cad11"},
      {"_GetResult_Request", "dc73121c18c39082c9aef18e46065ac3767f4bdb1f735e833130f36fceb3157e"},
      {"_GetResult_Response", "21fff52bf79b4a059d01c7af6ead4bf1749871057261c8422c067ed693159089"},
      {"_GetResult_Event", "79d2954ec184772ea17a47e88d6eaac4343b13e677a4dd3cdb440b0f9af70f3b"},
  };
  for (const auto& [suffix, hash] : published) {
    const std::string type = std::string("robot_interfaces/action/NavigateToGoal") + suffix;
    SCOPED_TRACE(type);
    auto h = rbsim::msgs::type_hash(type, source);
    ASSERT_TRUE(h.ok()) << h.error().message;
    EXPECT_EQ(h.value(), std::string("RIHS01_") + hash);
  }
  // The same file's hashes of the shipped types the action uses.
  EXPECT_EQ(rbsim::msgs::type_hash("unique_identifier_msgs/msg/UUID").value(),
            "RIHS01_1b8e8aca958cbea28fe6ef60bf6c19b683c97a9ef60bb34752067d0f2f7ab437");
  EXPECT_EQ(rbsim::msgs::type_hash("geometry_msgs/msg/PoseStamped").value(),
            "RIHS01_10f3786d7d40fd2b54367835614bff85d4ad3b5dab62bf8bca0cc232d73b4cd8");
  EXPECT_EQ(rbsim::msgs::type_hash("geometry_msgs/msg/Pose").value(),
            "RIHS01_d501954e9476cea2996984e812054b68026ae0bfae789d9a10b23daf35cc90fa");
  EXPECT_EQ(rbsim::msgs::type_hash("geometry_msgs/msg/Quaternion").value(),
            "RIHS01_8a765f66778c8ff7c8ab94afcc590a2ed5325a1d9a076ffff38fbce36f458684");
  EXPECT_EQ(rbsim::msgs::type_hash("geometry_msgs/msg/Point").value(),
            "RIHS01_6963084842a9b04494d6b2941d11444708d892da2f4b09843b9c43f42a7f6881");
  EXPECT_EQ(rbsim::msgs::type_hash("service_msgs/msg/ServiceEventInfo").value(),
            "RIHS01_41bcbbe07a75c9b52bc96bfd5c24d7f0fc0a08c0cb7921b3373c5732345a6f45");
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

// Every shipped type against rosbags, an implementation that is not ours: the table
// test/msgs/data/rihs01_rosbags.txt holds rosbags' hash of each (char as uint8, as rosidl), and
// test/python/check_type_hashes.py (CTest python.msgs.type_hashes_rosbags) checks on every run that
// rosbags still computes exactly that table from tools/msgs/definitions.
TEST(TypeHash, EveryShippedTypeMatchesRosbags) {
  std::ifstream in(std::filesystem::path(RBSIM_TEST_MSG_DATA) / "rihs01_rosbags.txt");
  ASSERT_TRUE(in) << "test/msgs/data/rihs01_rosbags.txt";
  std::map<std::string, std::string> table;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream words(line);
    std::string type, hash;
    words >> type >> hash;
    table[type] = hash;
  }
  const std::vector<std::string> types = every_shipped_type();
  EXPECT_EQ(table.size(), types.size());
  for (const std::string& t : types) {
    SCOPED_TRACE(t);
    const auto it = table.find(t);
    ASSERT_NE(it, table.end()) << "not in rihs01_rosbags.txt (regenerate: check_type_hashes.py --write)";
    auto h = rbsim::msgs::type_hash(t);
    ASSERT_TRUE(h.ok()) << h.error().message;
    EXPECT_EQ(h.value(), it->second);
  }
  // simulation_interfaces 2.1.0: 15 messages, 22 services, SimulateSteps.
  std::size_t simulation_interfaces = 0;
  for (const std::string& t : types) simulation_interfaces += t.starts_with("simulation_interfaces/") ? 1 : 0;
  EXPECT_EQ(simulation_interfaces, 15u + 22u * 4u + 13u);
}

TEST(TypeHash, EveryShippedTypeAndServiceHashes) {
  const std::vector<std::string> types = every_shipped_type();
  EXPECT_GE(rbsim::msgs::service_types().size(), 9u);  // rcl_interfaces' six, Trigger, Step, ApplyImpulse
  EXPECT_EQ(rbsim::msgs::action_types(),
            std::vector<std::string_view>{"simulation_interfaces/action/SimulateSteps"});
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
  // An action's goal_id is unique_identifier_msgs/UUID; a type no action derives is unknown.
  auto goal =
      rbsim::msgs::type_hash("a_msgs/action/A_SendGoal_Request", texts({{"a_msgs/action/A", "---\n---\n"}}));
  ASSERT_FALSE(goal.ok());
  EXPECT_NE(goal.error().message.find("unique_identifier_msgs/msg/UUID"), std::string::npos)
      << goal.error().message;
  for (const char* type :
       {"a_msgs/action/A_Request", "a_msgs/action/B_Goal", "a_msgs/action/A_SendGoal_Reply"}) {
    auto unknown = rbsim::msgs::type_hash(type, texts({{"a_msgs/action/A", "---\n---\n"}}));
    ASSERT_FALSE(unknown.ok()) << type;
    EXPECT_NE(unknown.error().message.find("no definition for"), std::string::npos)
        << unknown.error().message;
  }
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
      {"a_msgs/action/OneSep", "int32 a\n---\n"},
      {"a_msgs/action/ThreeSeps", "---\n---\n---\n"},
  };
  for (const auto& [type, text] : bad) {
    SCOPED_TRACE(type);
    std::string name = type;
    if (name.find("/srv/") != std::string::npos) name += "_Request";
    if (name.find("/action/") != std::string::npos) name += "_Feedback";
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
