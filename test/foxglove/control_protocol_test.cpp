// The Foxglove protocol's steering ops without a network: serverInfo's capabilities,
// advertiseServices, parameterValues (types as the Foxglove SDK writes them), the parameter ops
// and service call frames parsed (typing, hint, every malformed form), and the queue's count of
// what it never drops.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cstring>
#include <string>
#include <vector>

#include "rbsim/foxglove.hpp"

namespace rbsim::foxglove {
namespace {

using Json = nlohmann::json;
using V = msgs::ParameterValue;
using Op = ParameterRequest::Op;

std::string le32(std::uint32_t v) {
  std::string s(4, '\0');
  std::memcpy(s.data(), &v, 4);
  return s;
}
// A serviceCallRequest frame.
std::string call_frame(std::uint32_t service, std::uint32_t call, const std::string& encoding,
                       const std::string& payload, std::uint32_t encoding_size = UINT32_MAX) {
  return "\x02" + le32(service) + le32(call) +
         le32(encoding_size == UINT32_MAX ? static_cast<std::uint32_t>(encoding.size()) : encoding_size) +
         encoding + payload;
}

Json only_reply(const ClientProtocol::Outcome& o) {
  EXPECT_EQ(o.replies.size(), 1u);
  return o.replies.empty() ? Json() : Json::parse(o.replies[0]);
}

TEST(FoxgloveControlProtocol, ServerInfoOffersSteeringOnlyWithAController) {
  const Json with = Json::parse(server_info_json("rbsim", "1-1", true));
  EXPECT_EQ(with["capabilities"],
            Json::array({"time", "parameters", "parametersSubscribe", "services", "clientPublish"}));
  EXPECT_EQ(with["supportedEncodings"], Json::array({"cdr", "json"}));
  const Json without = Json::parse(server_info_json("rbsim", "1-1"));
  EXPECT_EQ(without["capabilities"], Json::array({"time"}));
  EXPECT_FALSE(without.contains("supportedEncodings"));
  const Json hosted = Json::parse(server_info_json("rbsim", "1-1", false, true));
  EXPECT_EQ(hosted["capabilities"], Json::array({"time", "services"}));
  EXPECT_EQ(hosted["supportedEncodings"], Json::array({"cdr", "json"}));
}

TEST(FoxgloveControlProtocol, AdvertiseServicesGivesBothSchemaForms) {
  const std::vector<ServiceSpec> specs = {
      {"/ns/step", "rbsim_msgs/srv/Step", "uint32 steps\n", "bool success\n"}};
  const Json j = Json::parse(advertise_services_json(specs));
  EXPECT_EQ(j["op"], "advertiseServices");
  ASSERT_EQ(j["services"].size(), 1u);
  const Json& s = j["services"][0];
  EXPECT_EQ(s["id"], 1);
  EXPECT_EQ(s["name"], "/ns/step");
  EXPECT_EQ(s["type"], "rbsim_msgs/srv/Step");
  EXPECT_EQ(s["request"], (Json{{"encoding", "cdr"},
                                {"schemaName", "rbsim_msgs/srv/Step_Request"},
                                {"schemaEncoding", "ros2msg"},
                                {"schema", "uint32 steps\n"}}));
  EXPECT_EQ(s["response"]["schemaName"], "rbsim_msgs/srv/Step_Response");
  EXPECT_EQ(s["response"]["schema"], "bool success\n");
  EXPECT_EQ(s["requestSchema"], "uint32 steps\n");
  EXPECT_EQ(s["responseSchema"], "bool success\n");
}

// A service's schemas are rosbag2's of its _Request and _Response: the part of the .srv text, then
// every type it uses, so a client decodes simulation_interfaces' nested replies on its own.
TEST(FoxgloveServiceSpec, SchemasCarryTheTypesTheyUse) {
  const ServiceSpec flat = service_spec("/ns", "step", "rbsim_msgs/srv/Step");
  EXPECT_EQ(flat.name, "/ns/step");
  EXPECT_EQ(flat.request_schema, msgs::ros2msg_schema("rbsim_msgs/srv/Step_Request").value());
  EXPECT_NE(flat.request_schema.find("uint32 steps"), std::string::npos);
  EXPECT_EQ(flat.request_schema.find("---"), std::string::npos);
  const ServiceSpec nested =
      service_spec("/ns", "get_entity_state", "simulation_interfaces/srv/GetEntityState");
  EXPECT_EQ(nested.type, "simulation_interfaces/srv/GetEntityState");
  EXPECT_NE(nested.request_schema.find("string entity"), std::string::npos);
  for (const char* dep : {"MSG: simulation_interfaces/Result", "MSG: simulation_interfaces/EntityState",
                          "MSG: std_msgs/Header", "MSG: geometry_msgs/Pose", "MSG: geometry_msgs/Quaternion",
                          "MSG: geometry_msgs/Twist", "MSG: builtin_interfaces/Time"}) {
    EXPECT_NE(nested.response_schema.find(dep), std::string::npos) << dep;
  }
  EXPECT_TRUE(service_spec("/ns", "x", "no_such/srv/Type").request_schema.empty());
}

TEST(FoxgloveControlProtocol, ParameterValuesTypeDoublesAsTheSdkDoes) {
  V bytes;
  bytes.type = msgs::ParameterType::ByteArray;
  V doubles;
  doubles.type = msgs::ParameterType::DoubleArray;
  doubles.double_array_value = {1.0, 2.5};
  V ints;
  ints.type = msgs::ParameterType::IntegerArray;
  ints.integer_array_value = {1, 2};
  std::vector<msgs::Parameter> ps = {{"d", V::of_double(2.0)},
                                     {"i", V::of_integer(7)},
                                     {"b", V::of_bool(true)},
                                     {"s", V::of_string("x")},
                                     {"ba", bytes},
                                     {"da", doubles},
                                     {"ia", ints}};
  for (const auto& [raw, encoded] : std::vector<std::pair<std::string, std::string>>{
           {"", ""}, {"A", "QQ=="}, {"AB", "QUI="}, {"ABC", "QUJD"}}) {
    ps[4].value.byte_array_value.assign(raw.begin(), raw.end());
    const Json j = Json::parse(parameter_values_json(ps, "req-1"));
    EXPECT_EQ(j["op"], "parameterValues");
    EXPECT_EQ(j["id"], "req-1");
    const Json& p = j["parameters"];
    EXPECT_EQ(p[0], (Json{{"name", "d"}, {"value", 2.0}, {"type", "float64"}}));
    EXPECT_TRUE(p[0]["value"].is_number_float());
    EXPECT_EQ(p[1], (Json{{"name", "i"}, {"value", 7}}));
    EXPECT_EQ(p[2], (Json{{"name", "b"}, {"value", true}}));
    EXPECT_EQ(p[3], (Json{{"name", "s"}, {"value", "x"}}));
    EXPECT_EQ(p[4], (Json{{"name", "ba"}, {"value", encoded}, {"type", "byte_array"}})) << raw;
    EXPECT_EQ(p[5], (Json{{"name", "da"}, {"value", {1.0, 2.5}}, {"type", "float64_array"}}));
    EXPECT_EQ(p[6], (Json{{"name", "ia"}, {"value", {1, 2}}}));
  }
  EXPECT_FALSE(Json::parse(parameter_values_json(ps))["parameters"].is_null());
  EXPECT_FALSE(Json::parse(parameter_values_json(ps)).contains("id"));
}

TEST(FoxgloveControlProtocol, ParameterOpsAreParsed) {
  ClientProtocol p(1, true, 0);
  ClientProtocol::Outcome o;
  p.handle_text(R"({"op":"getParameters","parameterNames":["a","b"],"id":"x"})", o);
  ASSERT_TRUE(o.parameters);
  EXPECT_TRUE(o.replies.empty());
  EXPECT_EQ(o.parameters->op, Op::Get);
  EXPECT_EQ(o.parameters->names, (std::vector<std::string>{"a", "b"}));
  EXPECT_EQ(o.parameters->id, "x");
  p.handle_text(R"({"op":"getParameters","parameterNames":[]})", o);
  ASSERT_TRUE(o.parameters);
  EXPECT_TRUE(o.parameters->names.empty());  // every parameter
  EXPECT_FALSE(o.parameters->id);
  p.handle_text(R"({"op":"subscribeParameterUpdates","parameterNames":["a"]})", o);
  ASSERT_TRUE(o.parameters);
  EXPECT_EQ(o.parameters->op, Op::Subscribe);
  p.handle_text(R"({"op":"unsubscribeParameterUpdates","parameterNames":[]})", o);
  ASSERT_TRUE(o.parameters);
  EXPECT_EQ(o.parameters->op, Op::Unsubscribe);
}

TEST(FoxgloveControlProtocol, SetValuesAreTypedAsJsonTypesThem) {
  ClientProtocol p(1, true, 0);
  ClientProtocol::Outcome o;
  p.handle_text(R"({"op":"setParameters","id":"s","parameters":[
      {"name":"i","value":2},{"name":"d","value":2.5},{"name":"h","value":3,"type":"float64"},
      {"name":"b","value":false},{"name":"s","value":"x"},{"name":"ba","value":"QUJD","type":"byte_array"},
      {"name":"ia","value":[1,2]},{"name":"da","value":[1,2.5]},{"name":"fa","value":[1,2],"type":"float64_array"},
      {"name":"sa","value":["a"]},{"name":"bo","value":[true]}]})",
                o);
  EXPECT_TRUE(o.replies.empty()) << o.replies[0];
  ASSERT_TRUE(o.parameters);
  const ParameterRequest& r = *o.parameters;
  EXPECT_EQ(r.op, Op::Set);
  EXPECT_EQ(r.id, "s");
  ASSERT_EQ(r.values.size(), 11u);
  EXPECT_EQ(r.values[0].value, V::of_integer(2));
  EXPECT_TRUE(r.untyped_integer[0]);
  EXPECT_EQ(r.values[1].value, V::of_double(2.5));
  EXPECT_EQ(r.values[2].value, V::of_double(3.0));
  EXPECT_FALSE(r.untyped_integer[2]);  // the hint says double
  EXPECT_EQ(r.values[3].value, V::of_bool(false));
  EXPECT_EQ(r.values[4].value, V::of_string("x"));
  EXPECT_EQ(r.values[5].value.type, msgs::ParameterType::ByteArray);
  EXPECT_EQ(r.values[5].value.byte_array_value, (std::vector<std::uint8_t>{'A', 'B', 'C'}));
  EXPECT_EQ(r.values[6].value.integer_array_value, (std::vector<std::int64_t>{1, 2}));
  EXPECT_EQ(r.values[7].value.double_array_value, (std::vector<double>{1.0, 2.5}));
  EXPECT_EQ(r.values[8].value.double_array_value, (std::vector<double>{1.0, 2.0}));
  EXPECT_EQ(r.values[9].value.type, msgs::ParameterType::StringArray);
  EXPECT_EQ(r.values[10].value.type, msgs::ParameterType::BoolArray);
}

TEST(FoxgloveControlProtocol, BadSetEntriesAreNamedAndTheRestStillApplies) {
  ClientProtocol p(1, true, 0);
  ClientProtocol::Outcome o;
  p.handle_text(R"({"op":"setParameters","parameters":[
      {"name":"ok","value":1.5},{"name":"unset"},{"name":"obj","value":{"a":1}},{"name":"mix","value":[1,"a"]},
      {"name":"b64","value":"Q=JD","type":"byte_array"},{"name":"hint","value":1,"type":"int64"},
      {"name":"f","value":"1","type":"float64"},{"value":3},{"name":"e","value":[]}]})",
                o);
  ASSERT_TRUE(o.parameters);
  ASSERT_EQ(o.parameters->values.size(), 1u);
  EXPECT_EQ(o.parameters->values[0].name, "ok");
  const Json s = only_reply(o);
  EXPECT_EQ(s["level"], 2);
  const std::string m = s["message"];
  for (const char* says :
       {"\"unset\": no value: parameters cannot be unset", "\"obj\": value", "\"mix\": an array must hold",
        "\"b64\": type byte_array: not valid base64", "\"hint\": unknown type \"int64\"", "and 3 more"}) {
    EXPECT_NE(m.find(says), std::string::npos) << says << " in " << m;
  }
}

TEST(FoxgloveControlProtocol, MalformedParameterOpsGetOneStatusError) {
  for (const auto& [frame, says] : std::vector<std::pair<std::string, std::string>>{
           {R"({"op":"getParameters"})", "\"parameterNames\" must be an array of strings"},
           {R"({"op":"getParameters","parameterNames":"a"})", "must be an array"},
           {R"({"op":"getParameters","parameterNames":[1]})", "parameter name 1 is not a string"},
           {R"({"op":"getParameters","parameterNames":[],"id":7})", "\"id\" must be a string"},
           {R"({"op":"setParameters","parameters":{}})", "\"parameters\" must be an array"},
           {R"({"op":"setParameters","parameters":[5]})", "needs a \"name\" string"},
           {R"({"op":"subscribeParameterUpdates"})", "must be an array"},
       }) {
    ClientProtocol p(1, true, 0);
    ClientProtocol::Outcome o;
    p.handle_text(frame, o);
    EXPECT_FALSE(o.parameters) << frame;
    const Json s = only_reply(o);
    EXPECT_EQ(s["level"], 2) << frame;
    EXPECT_NE(s["message"].get<std::string>().find(says), std::string::npos)
        << s["message"] << " for " << frame;
  }
}

TEST(FoxgloveControlProtocol, WithoutAControllerTheOpsAreNotSupported) {
  ClientProtocol p(1);
  ClientProtocol::Outcome o;
  for (const char* op :
       {"getParameters", "setParameters", "subscribeParameterUpdates", "unsubscribeParameterUpdates"}) {
    p.handle_text(std::string(R"({"op":")") + op + R"(","parameterNames":[],"parameters":[]})", o);
    EXPECT_FALSE(o.parameters);
    const Json s = only_reply(o);
    EXPECT_NE(s["message"].get<std::string>().find("not supported by this server (capabilities: time)"),
              std::string::npos)
        << s;
  }
  p.handle_binary(call_frame(1, 1, "cdr", ""), o);
  EXPECT_FALSE(o.call);
  EXPECT_NE(only_reply(o)["message"].get<std::string>().find("no client publishing or service calls"),
            std::string::npos);
}

TEST(FoxgloveControlProtocol, ServiceCallsAreParsed) {
  ClientProtocol p(1, true, 5);
  ClientProtocol::Outcome o;
  p.handle_binary(call_frame(4, 77, "cdr", std::string("\x00\x01\x00\x00\x05\x00\x00\x00", 8)), o);
  EXPECT_TRUE(o.replies.empty());
  ASSERT_TRUE(o.call);
  EXPECT_EQ(o.call->service, 4u);
  EXPECT_EQ(o.call->call, 77u);
  EXPECT_EQ(o.call->encoding, "cdr");
  EXPECT_EQ(o.call->payload.size(), 8u);
  p.handle_binary(call_frame(5, 78, "json", R"({"body":1})"), o);
  ASSERT_TRUE(o.call);
  EXPECT_EQ(o.call->encoding, "json");
  EXPECT_EQ(o.call->payload, R"({"body":1})");
}

TEST(FoxgloveControlProtocol, BadServiceCallsGetAFailureOrAStatus) {
  struct Bad {
    std::string frame;
    const char* op;
    const char* says;
  };
  for (const Bad& b : std::vector<Bad>{
           {call_frame(9, 3, "cdr", ""), "serviceCallFailure", "unknown service 9 (services are 1..5)"},
           {call_frame(0, 3, "cdr", ""), "serviceCallFailure", "unknown service 0"},
           {call_frame(1, 3, "ros1", ""), "serviceCallFailure", "unsupported encoding \"ros1\""},
           {call_frame(1, 3, "", ""), "serviceCallFailure", "unsupported encoding \"\""},
           {call_frame(1, 3, "cdr", "", 1000), "serviceCallFailure", "encoding length 1000 runs past"},
           {call_frame(1, 3, "cdr", std::string(kMaxClientFrame, 'x')), "serviceCallFailure", "the limit is"},
           {std::string("\x02\x01\x00", 3), "status", "its header alone is 13 bytes"},
           {"", "status", "service call requests (opcode 0x02) only"},
           {std::string("\x01\x07\x00\x00\x00\x01", 6), "status", "service call requests (opcode 0x02) only"},
           {std::string("\x04", 1), "status", "opcode 0x02"},
       }) {
    ClientProtocol p(1, true, 5);
    ClientProtocol::Outcome o;
    p.handle_binary(b.frame, o);
    EXPECT_FALSE(o.call);
    const Json j = only_reply(o);
    EXPECT_EQ(j["op"], b.op) << b.says;
    EXPECT_NE(j["message"].get<std::string>().find(b.says), std::string::npos) << j["message"];
    if (std::string(b.op) == "serviceCallFailure") {
      EXPECT_EQ(j["callId"], 3);
    }
  }
}

TEST(FoxgloveControlProtocol, ServiceCallResponseLayout) {
  std::string out;
  const std::byte payload[2] = {std::byte{0xAA}, std::byte{0xBB}};
  append_service_call_response(out, 3, 0x01020304, "cdr", payload);
  EXPECT_EQ(out, "\x03" + le32(3) + le32(0x01020304) + le32(3) + "cdr\xAA\xBB");
}

TEST(FoxgloveControlProtocol, TheQueueCountsWhatItNeverDrops) {
  ClientQueue q(QueueLimits{16, 1 << 20});
  q.push_text("abc");
  q.push_control("\x03xyz", true);
  const std::byte payload[10]{};
  q.push_message(ClientQueue::Kind::Latched, 1, 0, payload);
  q.push_message(ClientQueue::Kind::PerStep, 2, 0, payload);
  q.push_time(5);
  EXPECT_EQ(q.kept_bytes(), 3u + 4u + kMessageDataHeader + 10u);
  EXPECT_EQ(q.bytes(), q.kept_bytes() + kMessageDataHeader + 10u + 9u);  // per-step: droppable
  ClientQueue::Frame f;
  ASSERT_TRUE(q.pop(f));
  ASSERT_TRUE(q.pop(f));
  EXPECT_TRUE(f.binary);
  EXPECT_EQ(f.kind, ClientQueue::Kind::Control);
  EXPECT_EQ(q.kept_bytes(), kMessageDataHeader + 10u);
  q.remove_subscription(1);
  EXPECT_EQ(q.kept_bytes(), 0u);
}

}  // namespace
}  // namespace rbsim::foxglove
