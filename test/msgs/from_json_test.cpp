// MessageDecoder::from_json, the inverse of to_json: real service, action and parameter types
// round trip cdr -> to_json -> from_json to the same bytes; missing fields take their zero values;
// each rule's refusal names the field's path; hostile input is refused, never crashes.
#include <gtest/gtest.h>

#include <string>

#include "rbsim/interfaces.hpp"
#include "rbsim/msgs.hpp"
#include "rbsim/simulation_interfaces.hpp"
#include "spawn_world_samples.hpp"

namespace rbsim::msgs {
namespace {

MessageDecoder decoder(std::string_view type) {
  Result<std::string> schema = ros2msg_schema(type);
  EXPECT_TRUE(schema) << type;
  Result<MessageDecoder> d = MessageDecoder::create(type, schema ? schema.value() : "");
  EXPECT_TRUE(d) << d.error().message;
  return std::move(d.value());
}

// An action's SendGoal request (goal_id, then the goal), whose schema rosbag2 never writes: made
// here from the .action text as rosidl makes the message.
MessageDecoder send_goal_decoder() {
  const std::string action(simulation::SimulateStepsSendGoalRequest::kAction);
  const std::string_view text = definition(action);
  const std::string goal(text.substr(0, text.find("\n---")));
  const std::string rule = "\n" + std::string(80, '=') + "\nMSG: ";
  const std::string schema = "unique_identifier_msgs/UUID goal_id\n" + action + "_Goal goal\n" + rule +
                             "unique_identifier_msgs/UUID\n" +
                             std::string(definition("unique_identifier_msgs/msg/UUID")) + rule + action +
                             "_Goal\n" + goal + "\n";
  Result<MessageDecoder> d = MessageDecoder::create(action + "_SendGoal_Request", schema);
  EXPECT_TRUE(d) << d.error().message << "\n" << schema;
  return std::move(d.value());
}

// cdr -> to_json -> from_json gives the bytes back; returns the JSON.
std::string round_trip(const MessageDecoder& d, const Bytes& cdr) {
  std::string json;
  EXPECT_TRUE(d.to_json(cdr, json).ok());
  Bytes back;
  const Status st = d.from_json(json, back);
  EXPECT_TRUE(st.ok()) << st.error().message << "\n" << json;
  EXPECT_EQ(back, cdr) << json;
  return json;
}

std::string refusal(const MessageDecoder& d, std::string_view json) {
  Bytes out{std::byte{7}};
  const Status st = d.from_json(json, out);
  EXPECT_FALSE(st.ok()) << json;
  EXPECT_EQ(out, Bytes{std::byte{7}}) << "failure leaves the output as it was";
  return st.ok() ? "" : st.error().message;
}

TEST(MessageDecoderFromJson, RoundTripsNestedSequences) {
  simulation::GetEntitiesStatesResponse r;
  r.result.result = 1;
  r.result.error_message = "fine \"quoted\"\n";
  r.entities = {"body_0", "body_1", ""};
  for (int i = 0; i < 3; ++i) {
    simulation::EntityState s;
    s.stamp = {i, 1000u * static_cast<std::uint32_t>(i)};
    s.frame_id = "world";
    s.position = {0.1 * i, -2.5e-300, 1e300};
    s.orientation = {0.0, 0.0, 0.38268343236508978, 0.92387953251128674};
    s.linear_velocity = {1.0 / 3.0, i == 1 ? -0.0 : 1.0 * i, 7.0};  // -0.0 comes back with its sign
    r.states.push_back(s);
  }
  Bytes cdr;
  encode(r, cdr);
  const std::string json = round_trip(decoder("simulation_interfaces/srv/GetEntitiesStates_Response"), cdr);
  EXPECT_NE(json.find("\"entities\":[\"body_0\",\"body_1\",\"\"]"), std::string::npos) << json;
}

TEST(MessageDecoderFromJson, RoundTripsSetEntityStateRequest) {
  simulation::SetEntityStateRequest r;
  r.entity = "body_3";
  r.state.frame_id = "world";
  r.state.position = {1.5, -2.25, 0.0};
  r.state.angular_velocity = {0.0, 0.0, -4.0};
  r.set_pose = true;
  r.set_twist = true;
  Bytes cdr;
  encode(r, cdr);
  round_trip(decoder("simulation_interfaces/srv/SetEntityState_Request"), cdr);
}

// Spawning, deleting and worlds, every half filled: the schema-driven decoder of rosidl's message
// reads our encoding and gives the same bytes back.
TEST(MessageDecoderFromJson, RoundTripsSpawnAndWorldServices) {
  simulation::for_each_spawn_and_world_type([]<class T>(const T& m, std::string_view half) {
    const std::string type = simulation::rosidl_name<T>(half);
    SCOPED_TRACE(type);
    Bytes cdr;
    encode(m, cdr);
    round_trip(decoder(type), cdr);
  });
}

// Each field lands under its own name: our encoding read by the definition's schema.
TEST(MessageDecoderFromJson, SpawnAndWorldFieldsAreTheDefinitions) {
  const auto json = [](const auto& m, std::string_view type) {
    Bytes cdr;
    encode(m, cdr);
    std::string out;
    EXPECT_TRUE(decoder(type).to_json(cdr, out).ok()) << type;
    return out;
  };
  namespace sim = simulation;
  sim::SpawnEntity spawn = sim::some_spawn();
  spawn.initial_pose.orientation = {0.0, 0.0, 0.5, 0.75};
  EXPECT_EQ(
      json(sim::SpawnEntitiesRequest{{spawn}}, "simulation_interfaces/srv/SpawnEntities_Request"),
      R"({"spawn_requests":[{"name":"cart_1","allow_renaming":true,"entity_resource":)"
      R"({"uri":"file:///models/cart.sdf","resource_string":"<sdf version='1.9'><model name='cart'/></sdf>"},)"
      R"("entity_namespace":"/fleet","initial_pose":{"header":{"stamp":{"sec":7,"nanosec":250},)"
      R"("frame_id":"map"},"pose":{"position":{"x":1.5,"y":-2,"z":0.25},)"
      R"("orientation":{"x":0,"y":0,"z":0.5,"w":0.75}}}}]})");
  EXPECT_EQ(json(sim::SpawnEntitiesResponse{{150, "e"}, {sim::some_spawn_result()}},
                 "simulation_interfaces/srv/SpawnEntities_Response"),
            R"({"result":{"result":150,"error_message":"e"},"results":[{"result":{"result":101,)"
            R"("error_message":"cart_1 is taken"},"entity_name":"cart_1_2"}]})");
  EXPECT_EQ(
      json(sim::GetSpawnablesResponse{{1, ""}, {sim::some_spawnable()}},
           "simulation_interfaces/srv/GetSpawnables_Response"),
      R"({"result":{"result":1,"error_message":""},"spawnables":[{"entity_resource":)"
      R"({"uri":"file:///models/cart.sdf","resource_string":"<sdf version='1.9'><model name='cart'/></sdf>"},)"
      R"("description":"cart with a lidar","spawn_bounds":{"type":1,"points":)"
      R"([{"x":1,"y":1,"z":0.5},{"x":-1,"y":-1,"z":0}]}}]})");
  EXPECT_EQ(json(sim::GetCurrentWorldResponse{{1, ""}, sim::some_world()},
                 "simulation_interfaces/srv/GetCurrentWorld_Response"),
            R"({"result":{"result":1,"error_message":""},"world":{"name":"warehouse","world_resource":)"
            R"({"uri":"package://worlds/warehouse.sdf","resource_string":"<world/>"},)"
            R"("description":"a small warehouse","tags":["indoor","small"]}})");
  EXPECT_EQ(json(sim::GetAvailableWorldsRequest{{"s"}, {{"t"}, 1}, false, true},
                 "simulation_interfaces/srv/GetAvailableWorlds_Request"),
            R"({"additional_sources":["s"],"filter":{"tags":["t"],"filter_mode":1},"offline_only":false,)"
            R"("continue_on_error":true})");
  EXPECT_EQ(
      json(sim::LoadWorldRequest{{"u", "r"}, true, false}, "simulation_interfaces/srv/LoadWorld_Request"),
      R"({"world_resource":{"uri":"u","resource_string":"r"},"fail_on_unsupported_element":true,)"
      R"("ignore_missing_or_unsupported_assets":false})");
  EXPECT_EQ(json(sim::DeleteEntityRequest{"cart_1"}, "simulation_interfaces/srv/DeleteEntity_Request"),
            R"({"entity":"cart_1"})");
  EXPECT_EQ(json(sim::GetSpawnablesRequest{{"a", "b"}}, "simulation_interfaces/srv/GetSpawnables_Request"),
            R"({"sources":["a","b"]})");
  EXPECT_EQ(json(sim::SpawnEntityResponse{{109, "q"}, "n"}, "simulation_interfaces/srv/SpawnEntity_Response"),
            R"({"result":{"result":109,"error_message":"q"},"entity_name":"n"})");
}

// What a Foxglove Service Call panel sends: SpawnEntity's request, every field by its name in the
// .srv; the initial pose's quaternion as given (a missing w is 0, not the .msg's default 1).
TEST(MessageDecoderFromJson, SpawnEntityRequestFromJson) {
  Bytes cdr;
  const Status st = decoder("simulation_interfaces/srv/SpawnEntity_Request")
                        .from_json(R"({"name":"cart_1","allow_renaming":true,
                          "entity_resource":{"uri":"file:///models/cart.sdf","resource_string":"<sdf/>"},
                          "entity_namespace":"/fleet",
                          "initial_pose":{"header":{"stamp":{"sec":3,"nanosec":5},"frame_id":"map"},
                            "pose":{"position":{"x":1.5,"y":-2},"orientation":{"z":1}}}})",
                                   cdr);
  ASSERT_TRUE(st.ok()) << st.error().message;
  simulation::SpawnEntityRequest r;
  ASSERT_TRUE(decode(cdr, r).ok());
  EXPECT_EQ(r.name, "cart_1");
  EXPECT_TRUE(r.allow_renaming);
  EXPECT_EQ(r.entity_resource, (simulation::Resource{"file:///models/cart.sdf", "<sdf/>"}));
  EXPECT_EQ(r.entity_namespace, "/fleet");
  EXPECT_EQ(r.initial_pose.stamp, (Time{3, 5}));
  EXPECT_EQ(r.initial_pose.frame_id, "map");
  EXPECT_EQ(r.initial_pose.position, (simulation::Vector3{1.5, -2.0, 0.0}));
  EXPECT_EQ(r.initial_pose.orientation, (Quaternion{0.0, 0.0, 1.0, 0.0}));
  // SpawnEntities' request: a sequence of the SpawnEntity message, each as the request above.
  ASSERT_TRUE(decoder("simulation_interfaces/srv/SpawnEntities_Request")
                  .from_json(R"({"spawn_requests":[{"name":"a"},{"entity_resource":{"uri":"u"},
                                  "initial_pose":{"pose":{"orientation":{"w":1}}}}]})",
                             cdr)
                  .ok());
  simulation::SpawnEntitiesRequest many;
  ASSERT_TRUE(decode(cdr, many).ok());
  ASSERT_EQ(many.spawn_requests.size(), 2u);
  EXPECT_EQ(many.spawn_requests[0].name, "a");
  EXPECT_EQ(many.spawn_requests[1].entity_resource.uri, "u");
  EXPECT_EQ(many.spawn_requests[1].initial_pose.orientation, Quaternion{});
  EXPECT_EQ(refusal(decoder("simulation_interfaces/srv/SpawnEntity_Request"), R"({"allow_renaming":"yes"})"),
            "allow_renaming: must be true or false");
}

TEST(MessageDecoderFromJson, LoadWorldRequestFromJson) {
  const MessageDecoder d = decoder("simulation_interfaces/srv/LoadWorld_Request");
  Bytes cdr;
  ASSERT_TRUE(d.from_json(R"({"world_resource":{"resource_string":"<sdf><world name='w'/></sdf>"},
                              "ignore_missing_or_unsupported_assets":true})",
                          cdr)
                  .ok());
  simulation::LoadWorldRequest r;
  ASSERT_TRUE(decode(cdr, r).ok());
  EXPECT_EQ(r.world_resource, (simulation::Resource{"", "<sdf><world name='w'/></sdf>"}));
  EXPECT_FALSE(r.fail_on_unsupported_element);
  EXPECT_TRUE(r.ignore_missing_or_unsupported_assets);
  Bytes empty, zeros;
  ASSERT_TRUE(d.from_json("{}", empty).ok());
  encode(simulation::LoadWorldRequest{}, zeros);
  EXPECT_EQ(empty, zeros);
  EXPECT_EQ(refusal(d, R"({"world_resource":{"url":"x"}})"),
            "world_resource.url: no such field in simulation_interfaces/msg/Resource");
}

TEST(MessageDecoderFromJson, RoundTripsActionSendGoalWithItsFixedUuid) {
  simulation::SimulateStepsSendGoalRequest r;
  for (std::size_t i = 0; i < r.goal_id.size(); ++i) r.goal_id[i] = static_cast<std::uint8_t>(255 - 7 * i);
  r.steps = 18446744073709551615ull;  // uint64's max, beyond a double's precision
  Bytes cdr;
  encode(r, cdr);
  round_trip(send_goal_decoder(), cdr);
}

TEST(MessageDecoderFromJson, RoundTripsSetParametersWithByteArrays) {
  SetParametersRequest r;
  r.parameters.push_back({"gravity", ParameterValue::of_double(-9.81)});
  r.parameters.push_back({"name", ParameterValue::of_string("chain")});
  ParameterValue bytes;
  bytes.type = ParameterType::ByteArray;
  bytes.byte_array_value = {0, 1, 127, 128, 255};
  r.parameters.push_back({"blob", bytes});
  ParameterValue ints;
  ints.type = ParameterType::IntegerArray;
  ints.integer_array_value = {-9223372036854775807LL - 1, 0, 9223372036854775807LL};
  ints.bool_array_value = {true, false, true};
  ints.double_array_value = {0.5, -1e-310};
  ints.string_array_value = {"a", "b"};
  r.parameters.push_back({"ints", ints});
  Bytes cdr;
  encode(r, cdr);
  round_trip(decoder("rcl_interfaces/srv/SetParameters_Request"), cdr);
}

TEST(MessageDecoderFromJson, RoundTripsFloat32AndFixedArrays) {
  // A Marker: float32 colours, nested sequences; a ServiceEventInfo: char[16] and int8.
  const MessageDecoder marker = decoder("visualization_msgs/msg/Marker");
  Bytes cdr;
  ASSERT_TRUE(marker
                  .from_json(R"({"header":{"frame_id":"world"},"ns":"s","id":-3,"type":5,
                    "scale":{"x":0.1},"color":{"r":0.1,"g":0.2,"b":1,"a":0.7},
                    "points":[{"x":1,"y":2},{"x":-1e-5}],
                    "colors":[{"r":0.3,"a":1},{"g":3.4028234663852886e38}],"frame_locked":true})",
                             cdr)
                  .ok());
  const std::string json = round_trip(marker, cdr);
  EXPECT_NE(json.find("\"color\":{\"r\":0.1,\"g\":0.2,\"b\":1,\"a\":0.7}"), std::string::npos) << json;
  const MessageDecoder info = decoder("service_msgs/msg/ServiceEventInfo");
  ASSERT_TRUE(info.from_json(R"({"event_type":2,"client_gid":[1,2,3,4,5,6,7,8,9,10,11,12,13,14,15,255],
                                  "sequence_number":-5})",
                             cdr)
                  .ok());
  round_trip(info, cdr);
}

TEST(MessageDecoderFromJson, MissingFieldsTakeTheirZeroValues) {
  const MessageDecoder d = decoder("simulation_interfaces/srv/SetEntityState_Request");
  Bytes from_empty, zeros;
  ASSERT_TRUE(d.from_json("{}", from_empty).ok());
  simulation::SetEntityStateRequest defaults;
  defaults.state.orientation = {0.0, 0.0, 0.0, 0.0};  // zero, not the .msg's default w = 1
  encode(defaults, zeros);
  EXPECT_EQ(from_empty, zeros);
  Bytes partial;
  ASSERT_TRUE(
      d.from_json(R"({"entity":"body_1","state":{"pose":{"position":{"x":2}}},"set_pose":true})", partial)
          .ok());
  simulation::SetEntityStateRequest r;
  ASSERT_TRUE(decode(partial, r).ok());
  EXPECT_EQ(r.entity, "body_1");
  EXPECT_EQ(r.state.position.x, 2.0);
  EXPECT_EQ(r.state.orientation.w, 0.0);
  EXPECT_TRUE(r.set_pose);
  EXPECT_FALSE(r.set_twist);
  // A fixed array missing: all zeros; an empty message: rosidl's placeholder member.
  Bytes goal;
  ASSERT_TRUE(send_goal_decoder().from_json("{}", goal).ok());
  EXPECT_EQ(goal.size(), 4u + 16u + 8u);
  Bytes trigger;
  ASSERT_TRUE(decoder("std_srvs/srv/Trigger_Request").from_json("{}", trigger).ok());
  EXPECT_EQ(trigger.size(), 8u);  // header, one uint8, padding
}

TEST(MessageDecoderFromJson, RefusesEachBrokenRuleNamingTheField) {
  const MessageDecoder states = decoder("simulation_interfaces/srv/GetEntitiesStates_Response");
  EXPECT_EQ(refusal(states, R"({"states":[{},{},{"pose":{"position":{"x":"1"}}}]})"),
            "states[2].pose.position.x: must be a number (or null for NaN)");
  EXPECT_EQ(refusal(states, R"({"states":[{"pose":{"position":{"w":1}}}]})"),
            "states[0].pose.position.w: no such field in geometry_msgs/msg/Point");
  EXPECT_EQ(refusal(states, R"({"entities":"body_1"})"), "entities: must be an array");
  EXPECT_EQ(refusal(states, R"({"entities":[1]})"), "entities[0]: must be a string");
  EXPECT_EQ(refusal(states, R"({"result":[]})"),
            "result: must be a JSON object (a simulation_interfaces/msg/Result)");
  EXPECT_EQ(refusal(states, "[]"),
            "the message: must be a JSON object (a simulation_interfaces/srv/GetEntitiesStates_Response)");
  EXPECT_EQ(refusal(states, R"({"result":{"result":256}})"), "result.result: must be an integer in [0, 255]");
  EXPECT_EQ(refusal(states, R"({"result":{"result":-1}})"), "result.result: must be an integer in [0, 255]");
  EXPECT_EQ(refusal(states, R"({"result":{"result":1.5}})"), "result.result: must be an integer in [0, 255]");
  EXPECT_EQ(refusal(states, R"({"result":{"result":true}})"),
            "result.result: must be an integer in [0, 255]");
  EXPECT_EQ(refusal(states, R"({"states":[{"header":{"stamp":{"sec":2147483648}}}]})"),
            "states[0].header.stamp.sec: must be an integer in [-2147483648, 2147483647]");
  const MessageDecoder set = decoder("simulation_interfaces/srv/SetEntityState_Request");
  EXPECT_EQ(refusal(set, R"({"set_pose":1})"), "set_pose: must be true or false");
  EXPECT_EQ(refusal(set, R"({"state":{"pose":{"position":{"x":null}}},"set_pose":null})"),
            "set_pose: must be true or false");
  const MessageDecoder goal = send_goal_decoder();
  EXPECT_EQ(refusal(goal, R"({"goal_id":{"uuid":[1,2,3]}})"),
            "goal_id.uuid: must have exactly 16 elements, has 3");
  EXPECT_EQ(refusal(goal, R"({"goal_id":{"uuid":"AAEC"}})"),
            "goal_id.uuid: must have exactly 16 elements, has 3 (base64)");
  EXPECT_EQ(refusal(goal, R"({"goal_id":{"uuid":"not base64!"}})"),
            "goal_id.uuid: a string for bytes must be base64");
  EXPECT_EQ(refusal(goal, R"({"goal":{"steps":-1}})"),
            "goal.steps: must be an integer in [0, 18446744073709551615]");
  EXPECT_EQ(refusal(goal, R"({"goal":{"steps":1e20}})"),
            "goal.steps: must be an integer in [0, 18446744073709551615]");
  const MessageDecoder marker = decoder("visualization_msgs/msg/Marker");
  EXPECT_EQ(refusal(marker, R"({"color":{"r":1e39}})"), "color.r: must be within float32's range");
  // Bounds: a bounded sequence (ParameterDescriptor's ranges, [<=1]) and a bounded string.
  const MessageDecoder descriptor = decoder("rcl_interfaces/msg/ParameterDescriptor");
  EXPECT_EQ(refusal(descriptor, R"({"integer_range":[{},{}]})"),
            "integer_range: must have at most 1 elements, has 2");
  const MessageDecoder node = decoder("rmw_dds_common/msg/NodeEntitiesInfo");
  EXPECT_EQ(refusal(node, R"({"node_name":")" + std::string(257, 'n') + "\"}"),
            "node_name: must be at most 256 characters, has 257");
  // Not JSON, or too deep: refused before any field.
  EXPECT_NE(refusal(states, "{").find("not JSON: "), std::string::npos);
  EXPECT_NE(refusal(states, "").find("not JSON: "), std::string::npos);
  EXPECT_EQ(refusal(states, std::string(100000, '[')), "JSON nests deeper than 100 levels");
}

TEST(MessageDecoderFromJson, AcceptsIntegralFloatsNullNanAndBase64Bytes) {
  const MessageDecoder goal = send_goal_decoder();
  Bytes a, b;
  ASSERT_TRUE(
      goal.from_json(R"({"goal_id":{"uuid":"AAECAwQFBgcICQoLDA0ODw=="},"goal":{"steps":1e3}})", a).ok());
  ASSERT_TRUE(
      goal.from_json(R"({"goal_id":{"uuid":[0,1,2,3,4,5,6,7,8,9,10,11,12,13,14,15]},"goal":{"steps":1000}})",
                     b)
          .ok());
  EXPECT_EQ(a, b);
  simulation::SimulateStepsSendGoalRequest r;
  ASSERT_TRUE(decode(a, r).ok());
  EXPECT_EQ(r.steps, 1000u);
  EXPECT_EQ(r.goal_id[15], 15);
  // null is NaN, written by to_json as null again.
  const MessageDecoder point = decoder("geometry_msgs/msg/Point");
  Bytes p;
  ASSERT_TRUE(point.from_json(R"({"x":null,"y":1,"z":-2.5})", p).ok());
  std::string json;
  ASSERT_TRUE(point.to_json(p, json).ok());
  EXPECT_EQ(json, R"({"x":null,"y":1,"z":-2.5})");
}

}  // namespace
}  // namespace rbsim::msgs
