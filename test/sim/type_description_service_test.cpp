// <node>/get_type_description (type_description_interfaces/srv/GetTypeDescription), as rclcpp
// serves it: a node of this process (a Controller, its NodeServices and its DDS sink's publishers)
// called as a ROS 2 client calls it, over DDS (the loopback configuration) and in memory. The
// hash asked for is the one the node's endpoint announces: on DDS its writer's USER_DATA
// ("typehash=RIHS01_...;", read from DDS discovery), in memory the type the graph lists. Also
// the node type cache (rbsim/node_types.hpp) and the hash parser on their own.
#include <dds/dds.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cstring>
#include <set>
#include <string>
#include <thread>

#include "control_test_util.hpp"
#include "rbsim/dds.hpp"
#include "rbsim/dds_sink.hpp"
#include "rbsim/memory_middleware.hpp"
#include "rbsim/node_services.hpp"
#include "rbsim/node_types.hpp"
#include "rbsim/type_hash.hpp"
#include "sim_test_util.hpp"

namespace rbsim::node {
namespace {

using namespace std::chrono_literals;
using msgs::GetTypeDescriptionRequest;
using msgs::GetTypeDescriptionResponse;

constexpr std::uint32_t kDomain = 161;  // its own: test/dds has 143..157, test/middleware 158, test/sim 159
constexpr std::string_view kBodyStates = "rbsim_msgs/msg/BodyStates";

std::string hash_of(std::string_view type) {
  const Result<std::string> h = msgs::type_hash(type);
  if (!h) throw std::runtime_error(h.error().message);
  return h.value();
}

// --- The cache and the parser -----------------------------------------------------------------

TEST(NodeTypeCache, HoldsATypeWhileAnyRegistrationLives) {
  auto cache = std::make_shared<NodeTypeCache>();
  {
    TypeRegistration a = NodeTypeCache::register_type(cache, "std_msgs/msg/Header");
    TypeRegistration b = NodeTypeCache::register_type(cache, "std_msgs/msg/Header");
    TypeRegistration c = NodeTypeCache::register_type(cache, "std_srvs/srv/Trigger");
    EXPECT_EQ(cache->types(), (std::vector<std::string>{"std_msgs/msg/Header", "std_srvs/srv/Trigger"}));
    EXPECT_EQ(cache->find(hash_of("std_srvs/srv/Trigger")), "std_srvs/srv/Trigger");
    EXPECT_EQ(cache->find(hash_of("std_srvs/srv/Trigger_Request")), std::nullopt);  // rcl's: the service's
    { TypeRegistration gone = std::move(a); }
    EXPECT_EQ(cache->find(hash_of("std_msgs/msg/Header")), "std_msgs/msg/Header");  // b still holds it
    b = TypeRegistration();
    EXPECT_EQ(cache->find(hash_of("std_msgs/msg/Header")), std::nullopt);
    // A type rbsim cannot describe is not registered (rcl has no type support for it either).
    TypeRegistration foreign = NodeTypeCache::register_type(cache, "other_msgs/msg/Unknown");
    EXPECT_EQ(cache->types(), std::vector<std::string>{"std_srvs/srv/Trigger"});
  }
  EXPECT_TRUE(cache->types().empty());
}

TEST(ParseTypeHash, ReadsWhatRosidlReads) {
  const std::string h = hash_of("std_msgs/msg/Header");
  EXPECT_EQ(parse_type_hash(h), h);
  std::string upper = h;
  for (std::size_t i = 7; i < upper.size(); ++i) upper[i] = static_cast<char>(std::toupper(upper[i]));
  EXPECT_EQ(parse_type_hash(upper), h);                    // hex digits in either case
  EXPECT_EQ(parse_type_hash("RIHS01-" + h.substr(7)), h);  // rosidl never looks at the separator
  EXPECT_EQ(parse_type_hash(h.substr(0, 70)), std::nullopt);
  EXPECT_EQ(parse_type_hash(h + "0"), std::nullopt);
  EXPECT_EQ(parse_type_hash("RIHS02_" + h.substr(7)), std::nullopt);  // an unknown version
  EXPECT_EQ(parse_type_hash("rihs01_" + h.substr(7)), std::nullopt);
  EXPECT_EQ(parse_type_hash(h.substr(0, 70) + "g"), std::nullopt);
  EXPECT_EQ(parse_type_hash(""), std::nullopt);
}

// --- The service on a node ---------------------------------------------------------------------

// A node of this process with rbsim node's endpoints (its DDS sink's publishers, its services and
// their publishers), and a client participant.
class GetTypeDescriptionService : public ::testing::TestWithParam<std::string> {
 protected:
  void SetUp() override {
    node_ = test::node_name("type_description");
    server_.emplace(participant(node_));
    NodeOptions sink_options;
    sink_options.ns = node_;
    auto sink = DdsSink::create(*server_, sink_options);
    ASSERT_TRUE(sink.ok()) << sink.error().message;
    sink_ = std::move(sink.value());
    client_.emplace(participant(node_ + "_client"));
  }
  void start_services(bool type_description) {
    NodeServicesOptions options{"/" + node_};
    options.start_type_description_service = type_description;
    auto services = NodeServices::create(*server_, controller_, options);
    ASSERT_TRUE(services.ok()) << services.error().message;
    services_ = std::move(services.value());
  }

  Participant participant(const std::string& name) {
    return test::participant(GetParam(), network_, kDomain, name);
  }

  Result<ServiceClient> client() {
    return ServiceClient::create(*client_, "/" + node_ + "/get_type_description",
                                 GetTypeDescriptionRequest::kService);
  }
  GetTypeDescriptionResponse call(const GetTypeDescriptionRequest& req) {
    auto c = client();
    if (!c) throw std::runtime_error(c.error().message);
    if (Status st = c.value().wait_for_server(20.0); !st) throw std::runtime_error(st.error().message);
    Bytes body;
    encode(req, body);
    Result<Bytes> reply = c.value().call(body, 20.0);
    if (!reply) throw std::runtime_error(reply.error().message);
    GetTypeDescriptionResponse res;
    if (Status st = decode(std::span<const std::byte>(reply.value()), res); !st)
      throw std::runtime_error(st.error().message);
    return res;
  }

  // The hash the node's writer on `topic` announces: DDS discovery's USER_DATA of that writer,
  // seen from the client's participant; in memory, the hash of the type the graph lists.
  std::string announced_hash(const std::string& topic) {
    if (GetParam() == "memory") {
      for (const MemoryNetwork::Node& n : network_->graph()) {
        if (n.name.name != node_) continue;
        for (const MemoryNetwork::Endpoint& e : n.endpoints)
          if (e.kind == MemoryNetwork::Endpoint::Kind::Publisher && e.name == topic) return hash_of(e.type);
      }
      return {};
    }
    const dds_entity_t reader =
        dds_create_reader(dds_entity(*client_), DDS_BUILTIN_TOPIC_DCPSPUBLICATION, nullptr, nullptr);
    std::string found;
    for (int attempt = 0; attempt < 200 && found.empty(); ++attempt) {
      void* samples[256] = {};
      dds_sample_info_t infos[256];
      const dds_return_t n = dds_read(reader, samples, infos, 256, 256);
      for (dds_return_t i = 0; i < n; ++i) {
        const auto* e = static_cast<const dds_builtintopic_endpoint_t*>(samples[i]);
        if (!infos[i].valid_data || std::string(e->topic_name) != "rt" + topic) continue;
        void* ud = nullptr;
        std::size_t size = 0;
        if (e->qos != nullptr && dds_qget_userdata(e->qos, &ud, &size) && ud != nullptr) {
          found.assign(static_cast<const char*>(ud), size);
          dds_free(ud);
        }
      }
      if (n > 0) dds_return_loan(reader, samples, n);
      if (found.empty()) std::this_thread::sleep_for(50ms);
    }
    dds_delete(reader);
    // "typehash=RIHS01_<64 hex>;", the whole USER_DATA of a topic's writer.
    if (!found.starts_with("typehash=") || !found.ends_with(";")) return {};
    return found.substr(9, found.size() - 10);
  }

  const Scene scene_ = test::control_scene();
  control::Controller controller_{scene_, 1000, control::RunSettings{1.0, 1, true}};
  std::shared_ptr<MemoryNetwork> network_ = std::make_shared<MemoryNetwork>();
  std::string node_;
  std::optional<Participant> server_, client_;
  std::unique_ptr<DdsSink> sink_;
  std::unique_ptr<NodeServices> services_;
};

TEST_P(GetTypeDescriptionService, DescribesATypeTheNodePublishesByItsAnnouncedHash) {
  start_services(true);
  const std::string announced = announced_hash("/" + node_ + "/body_states");
  ASSERT_EQ(announced, hash_of(kBodyStates));
  const GetTypeDescriptionResponse res = call({std::string(kBodyStates), announced, true});
  ASSERT_TRUE(res.successful) << res.failure_reason;
  EXPECT_EQ(res.failure_reason, "");
  EXPECT_EQ(res.type_description.type_description.type_name, kBodyStates);
  // The description is the whole type: its hash is the announced one.
  EXPECT_EQ(msgs::type_hash(res.type_description).value(), announced);
  EXPECT_EQ(res.type_description, msgs::type_description(kBodyStates).value());
  // The sources: the type's .msg text first, then each referenced type's.
  ASSERT_EQ(res.type_sources.size(), 1 + res.type_description.referenced_type_descriptions.size());
  EXPECT_EQ(res.type_sources[0].type_name, kBodyStates);
  EXPECT_EQ(res.type_sources[0].encoding, "msg");
  EXPECT_EQ(res.type_sources[0].raw_file_contents + "\n", *msgs::shipped_definition(kBodyStates));
  EXPECT_TRUE(res.extra_information.empty());

  // Without the sources.
  const GetTypeDescriptionResponse bare = call({std::string(kBodyStates), announced, false});
  ASSERT_TRUE(bare.successful);
  EXPECT_TRUE(bare.type_sources.empty());
  EXPECT_EQ(bare.type_description, res.type_description);
}

// The cache is what the node created: every type of its endpoints (in memory, the graph lists
// them all: publishers, and services by their service type) is described, and nothing else.
TEST_P(GetTypeDescriptionService, EveryTypeOfTheNodesEndpointsIsDescribed) {
  start_services(true);
  const std::vector<std::string> types = server_->types()->types();
  for (const char* expected :
       {"rbsim_msgs/msg/BodyStates", "rbsim_msgs/msg/Command", "rcl_interfaces/msg/ParameterEvent",
        "rcl_interfaces/srv/GetParameters", "std_srvs/srv/Trigger", "rbsim_msgs/srv/Step",
        "simulation_interfaces/srv/GetEntities", "type_description_interfaces/srv/GetTypeDescription"}) {
    EXPECT_NE(std::find(types.begin(), types.end(), expected), types.end()) << expected;
  }
  for (const std::string& type : types) {
    const GetTypeDescriptionResponse res = call({type, hash_of(type), false});
    ASSERT_TRUE(res.successful) << type << ": " << res.failure_reason;
    EXPECT_EQ(res.type_description.type_description.type_name, type);
  }
  if (GetParam() == "memory") {
    std::set<std::string> listed;
    for (const MemoryNetwork::Node& n : network_->graph()) {
      if (n.name.name != node_) continue;
      for (const MemoryNetwork::Endpoint& e : n.endpoints) listed.insert(e.type);
    }
    EXPECT_EQ(listed, std::set<std::string>(types.begin(), types.end()));
  }
  // A publisher that goes takes its type with it (the sink's are the only BodyStates writer).
  sink_.reset();
  const GetTypeDescriptionResponse gone = call({std::string(kBodyStates), hash_of(kBodyStates), false});
  EXPECT_FALSE(gone.successful);
  EXPECT_EQ(gone.failure_reason, "Type not currently in use by this node");
}

// rcl's answers: by hash alone, in rcl's words.
TEST_P(GetTypeDescriptionService, UnknownTypeOrBadHashFailsAsRclSays) {
  start_services(true);
  // A type the node does not use (a type it only refers to, inside its markers).
  GetTypeDescriptionResponse res = call({"std_msgs/msg/ColorRGBA", hash_of("std_msgs/msg/ColorRGBA"), true});
  EXPECT_FALSE(res.successful);
  EXPECT_EQ(res.failure_reason, "Type not currently in use by this node");
  EXPECT_EQ(res.type_description, msgs::TypeDescription{});
  EXPECT_TRUE(res.type_sources.empty());
  // The node's type with a hash one digit off.
  std::string wrong = hash_of(kBodyStates);
  wrong.back() = wrong.back() == '0' ? '1' : '0';
  res = call({std::string(kBodyStates), wrong, true});
  EXPECT_FALSE(res.successful);
  EXPECT_EQ(res.failure_reason, "Type not currently in use by this node");
  for (const std::string& bad :
       std::vector<std::string>{"", "RIHS01_", "RIHS01_xyz", "RIHS02_" + hash_of(kBodyStates).substr(7)}) {
    res = call({std::string(kBodyStates), bad, true});
    EXPECT_FALSE(res.successful) << bad;
    EXPECT_EQ(res.failure_reason, "Failed to parse type hash") << bad;
  }
  // rcl looks the type up by its hash and never at type_name: a name that does not match still
  // gets the hash's type.
  res = call({"std_msgs/msg/String", hash_of(kBodyStates), false});
  EXPECT_TRUE(res.successful);
  EXPECT_EQ(res.type_description.type_description.type_name, kBodyStates);
  // A request that does not decode is answered, naming what is wrong.
  auto c = client();
  ASSERT_TRUE(c.ok());
  ASSERT_TRUE(c.value().wait_for_server(20.0).ok());
  // A CDR header, then one byte where a string's length belongs.
  const Bytes truncated{std::byte{0}, std::byte{1}, std::byte{0}, std::byte{0}, std::byte{0xff}};
  Result<Bytes> reply = c.value().call(truncated, 20.0);
  ASSERT_TRUE(reply.ok()) << reply.error().message;
  ASSERT_TRUE(decode(std::span<const std::byte>(reply.value()), res).ok());
  EXPECT_FALSE(res.successful);
  EXPECT_NE(res.failure_reason.find("type_description_interfaces/srv/GetTypeDescription request"),
            std::string::npos)
      << res.failure_reason;
}

// start_type_description_service false (rclcpp's read-only parameter, given by an override):
// no service, and its type is not among the node's.
TEST_P(GetTypeDescriptionService, ParameterFalseLeavesTheServiceOut) {
  start_services(false);
  auto c = client();
  ASSERT_TRUE(c.ok());
  EXPECT_FALSE(c.value().wait_for_server(1.0).ok());
  const std::vector<std::string> types = server_->types()->types();
  EXPECT_EQ(std::find(types.begin(), types.end(), GetTypeDescriptionRequest::kService), types.end());
  EXPECT_NE(std::find(types.begin(), types.end(), "rcl_interfaces/srv/GetParameters"), types.end());
}

INSTANTIATE_TEST_SUITE_P(Middleware, GetTypeDescriptionService, ::testing::Values("dds", "memory"),
                         [](const ::testing::TestParamInfo<std::string>& p) { return p.param; });

}  // namespace
}  // namespace rbsim::node
