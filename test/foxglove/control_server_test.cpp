// The Foxglove server steering a run over loopback sockets: a Controller driving a real run loop
// (the control tests' scene, started paused), clients of ws_client.hpp. Every op answered through
// the controller (parameters read, set, typed and refused; updates to subscribers only; the five
// services in cdr and json, their refusals), and the bounds that keep a hostile client from
// hurting the run (commands in flight, a reply backlog, a server gone before its answers).
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <chrono>
#include <cstring>
#include <future>
#include <thread>

#include "../control/control_test_util.hpp"
#include "rbsim/foxglove.hpp"
#include "rbsim/simulation_interfaces.hpp"
#include "ws_client.hpp"

namespace rbsim::foxglove {
namespace {

using Json = nlohmann::json;
using test::WsClient;
using namespace std::chrono_literals;

std::string le32(std::uint32_t v) {
  std::string s(4, '\0');
  std::memcpy(s.data(), &v, 4);
  return s;
}
std::string call_frame(std::uint32_t service, std::uint32_t call, const std::string& encoding,
                       const std::string& payload) {
  return "\x02" + le32(service) + le32(call) + le32(static_cast<std::uint32_t>(encoding.size())) + encoding +
         payload;
}
std::string cdr_text(const Bytes& b) {
  return {reinterpret_cast<const char*>(b.data()), b.size()};
}
template <class T>
std::string cdr(const T& message) {
  Bytes b;
  msgs::encode(message, b);
  return cdr_text(b);
}

// A run of the control scene (started paused at step 0, as fast as possible once resumed, long
// enough to outlast a test) with its controller, on a thread, and a server steering it.
constexpr std::int64_t kSteps = 100'000'000;
struct Steered {
  Scene scene = rbsim::test::control_scene();
  control::Controller controller{scene, kSteps, control::RunSettings{0.0, 1, true}};
  std::unique_ptr<Server> server;
  std::thread loop;
  explicit Steered(ServerOptions o = {}, bool run = true) {
    o.address = "127.0.0.1";
    o.port = 0;
    o.steering = &controller;
    o.node = "/sim";
    auto s = Server::start(o, {});
    EXPECT_TRUE(s) << (s ? "" : s.error().message);
    if (s) server = std::move(s.value());
    if (!run) return;
    loop = std::thread([this] {
      Result<Driver> driver = Driver::create(scene);
      if (!driver) return;
      DriverOptions options;
      options.steps = kSteps;
      options.control = &controller;
      (void)driver.value().run_pass(options);
    });
  }
  ~Steered() {
    controller.close("the test ended");
    if (loop.joinable()) loop.join();
    server.reset();
  }
};

// Reads frames (at most 100, each within the client's 5 s timeout) until one satisfies `want`.
template <class P>
std::optional<WsClient::Frame> read_until(WsClient& c, P want) {
  for (int i = 0; i < 100; ++i) {
    auto f = c.read();
    if (!f) return std::nullopt;
    if (want(*f)) return f;
  }
  return std::nullopt;
}
// The next text frame with op `op`.
Json next_op(WsClient& c, const std::string& op) {
  auto f = read_until(c, [&](const WsClient::Frame& g) {
    return g.opcode == 1 && Json::parse(g.data, nullptr, false).value("op", "") == op;
  });
  return f ? Json::parse(f->data) : Json();
}
struct Response {
  std::uint32_t service = 0, call = 0;
  std::string encoding, payload;
};
std::optional<Response> next_response(WsClient& c) {
  auto f = read_until(
      c, [](const WsClient::Frame& g) { return g.opcode == 2 && !g.data.empty() && g.data[0] == 3; });
  if (!f || f->data.size() < 13) return std::nullopt;
  Response r;
  std::uint32_t n = 0;
  std::memcpy(&r.service, f->data.data() + 1, 4);
  std::memcpy(&r.call, f->data.data() + 5, 4);
  std::memcpy(&n, f->data.data() + 9, 4);
  r.encoding = f->data.substr(13, n);
  r.payload = f->data.substr(13 + n);
  return r;
}
Json connect(WsClient& c, std::uint16_t port) {
  EXPECT_EQ(c.connect(port, {"foxglove.websocket.v1"}), 101);
  const Json info = next_op(c, "serverInfo");
  EXPECT_FALSE(next_op(c, "advertise").is_null());
  return info;
}
Json value_of(const Json& values, const std::string& name) {
  for (const Json& p : values["parameters"]) {
    if (p["name"] == name) return p;
  }
  return Json();
}

TEST(FoxgloveSteering, AdvertisesTheCapabilitiesAndTheFiveServices) {
  Steered s;
  ASSERT_TRUE(s.server);
  WsClient c;
  const Json info = connect(c, s.server->port());
  EXPECT_EQ(info["capabilities"],
            Json::array({"time", "parameters", "parametersSubscribe", "services", "clientPublish"}));
  EXPECT_EQ(info["supportedEncodings"], Json::array({"cdr", "json"}));
  const Json services = next_op(c, "advertiseServices")["services"];
  ASSERT_EQ(services.size(), 5u);
  const char* names[] = {"/sim/pause", "/sim/resume", "/sim/reset", "/sim/step", "/sim/apply_impulse"};
  for (std::size_t i = 0; i < 5; ++i) {
    EXPECT_EQ(services[i]["id"], i + 1);
    EXPECT_EQ(services[i]["name"], names[i]);
  }
  EXPECT_EQ(services[3]["type"], "rbsim_msgs/srv/Step");
  EXPECT_NE(services[3]["request"]["schema"].get<std::string>().find("uint32 steps"), std::string::npos);
  EXPECT_EQ(services[3]["request"]["schema"].get<std::string>().find("---"), std::string::npos);
  EXPECT_NE(services[3]["response"]["schema"].get<std::string>().find("uint64 step"), std::string::npos);
  EXPECT_EQ(services[0]["requestSchema"].get<std::string>().find("bool"),
            std::string::npos);  // Trigger: empty
  EXPECT_NE(services[0]["responseSchema"].get<std::string>().find("string message"), std::string::npos);
}

TEST(FoxgloveSteering, GetsSetsAndUpdatesParameters) {
  Steered s;
  ASSERT_TRUE(s.server);
  WsClient c, watcher, other;
  connect(c, s.server->port());
  connect(watcher, s.server->port());
  connect(other, s.server->port());
  ASSERT_TRUE(c.send_text(R"({"op":"getParameters","parameterNames":[],"id":"all"})"));
  const Json all = next_op(c, "parameterValues");
  EXPECT_EQ(all["id"], "all");
  EXPECT_EQ(all["parameters"].size(), s.controller.list({}, 0).names.size());
  EXPECT_EQ(value_of(all, "forces.0.fy"),
            (Json{{"name", "forces.0.fy"}, {"value", -9.81}, {"type", "float64"}}));
  EXPECT_EQ(value_of(all, "bodies"), (Json{{"name", "bodies"}, {"value", 2}}));
  EXPECT_EQ(value_of(all, "paused")["value"], true);

  ASSERT_TRUE(watcher.send_text(R"({"op":"subscribeParameterUpdates","parameterNames":["forces.0.fy"]})"));
  ASSERT_TRUE(watcher.send_text(R"({"op":"getParameters","parameterNames":["forces.0.fy"],"id":"sync"})"));
  ASSERT_EQ(next_op(watcher, "parameterValues")["id"], "sync");  // the subscription is in place
  // -3 is a JSON integer: for the double forces.0.fy it is -3.0.
  ASSERT_TRUE(
      c.send_text(R"({"op":"setParameters","parameters":[{"name":"forces.0.fy","value":-3}],"id":"set"})"));
  const Json set = next_op(c, "parameterValues");
  EXPECT_EQ(set["id"], "set");
  EXPECT_EQ(set["parameters"],
            Json::array({{{"name", "forces.0.fy"}, {"value", -3.0}, {"type", "float64"}}}));
  const Json update = next_op(watcher, "parameterValues");
  EXPECT_FALSE(update.contains("id"));
  EXPECT_EQ(update["parameters"], set["parameters"]);
  EXPECT_EQ(s.controller.get({"forces.0.fy"})[0], msgs::ParameterValue::of_double(-3.0));

  // A client that did not subscribe gets no update: its next parameterValues is its own answer.
  ASSERT_TRUE(other.send_text(R"({"op":"getParameters","parameterNames":["bodies"],"id":"mine"})"));
  EXPECT_EQ(next_op(other, "parameterValues")["id"], "mine");
  // Unsubscribed: no update for the next change.
  ASSERT_TRUE(watcher.send_text(R"({"op":"unsubscribeParameterUpdates","parameterNames":[]})"));
  ASSERT_TRUE(
      c.send_text(R"({"op":"setParameters","parameters":[{"name":"forces.0.fy","value":-2.5}],"id":"2"})"));
  EXPECT_EQ(next_op(c, "parameterValues")["id"], "2");
  ASSERT_TRUE(watcher.send_text(R"({"op":"getParameters","parameterNames":["forces.0.fy"],"id":"after"})"));
  const Json after = next_op(watcher, "parameterValues");
  EXPECT_EQ(after["id"], "after");
  EXPECT_EQ(value_of(after, "forces.0.fy")["value"], -2.5);
}

TEST(FoxgloveSteering, RefusedSetsAreNamedAndTheRestApplies) {
  Steered s;
  ASSERT_TRUE(s.server);
  WsClient c;
  connect(c, s.server->port());
  ASSERT_TRUE(c.send_text(R"({"op":"setParameters","id":"mixed","parameters":[
      {"name":"springs.0.k","value":7.5},{"name":"bodies","value":3},{"name":"rate","value":"fast"},
      {"name":"nope","value":1.0},{"name":"publish_every","value":2.0},{"name":"forces.1.beta","value":-1.0}]})"));
  const Json answer = next_op(c, "parameterValues");
  EXPECT_EQ(answer["id"], "mixed");
  EXPECT_EQ(value_of(answer, "springs.0.k")["value"], 7.5);
  EXPECT_EQ(value_of(answer, "bodies")["value"], 2);  // unchanged: its current value
  EXPECT_TRUE(value_of(answer, "nope").is_null());
  const Json status = next_op(c, "status");
  EXPECT_EQ(status["level"], 2);
  const std::string m = status["message"];
  for (const char* says : {"bodies", "rate", "nope", "publish_every", "forces.1.beta"}) {
    EXPECT_NE(m.find(says), std::string::npos) << says << " in " << m;
  }
  EXPECT_EQ(m.find("springs.0.k"), std::string::npos) << m;
  EXPECT_EQ(s.controller.get({"springs.0.k"})[0], msgs::ParameterValue::of_double(7.5));
  // A request naming more values than the node has parameters is refused whole.
  std::string many = R"({"op":"setParameters","id":"many","parameters":[)";
  for (int k = 0; k < 10000; ++k) many += std::string(k ? "," : "") + R"({"name":"rate","value":2.0})";
  ASSERT_TRUE(c.send_text(many + "]}"));
  EXPECT_NE(next_op(c, "status")["message"].get<std::string>().find("10000 values in one request, more than"),
            std::string::npos);
  EXPECT_EQ(s.controller.get({"rate"})[0], msgs::ParameterValue::of_double(0.0));
  // Unknown names in a read are named too; the known ones still come.
  ASSERT_TRUE(c.send_text(R"({"op":"getParameters","parameterNames":["dt","ghost"],"id":"g"})"));
  EXPECT_EQ(next_op(c, "parameterValues")["parameters"].size(), 1u);
  EXPECT_NE(next_op(c, "status")["message"].get<std::string>().find("no parameter 'ghost'"),
            std::string::npos);
}

TEST(FoxgloveSteering, ServicesInCdrAndJsonMoveTheRun) {
  Steered s;
  ASSERT_TRUE(s.server);
  WsClient c;
  connect(c, s.server->port());
  ASSERT_TRUE(c.send_text(R"({"op":"subscribeParameterUpdates","parameterNames":["paused"]})"));
  // step 5 while paused (cdr): applied at step 0, then the run pauses again at 5.
  ASSERT_TRUE(c.send_binary(call_frame(4, 11, "cdr", cdr(msgs::StepRequest{5}))));
  auto r = next_response(c);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->service, 4u);
  EXPECT_EQ(r->call, 11u);
  EXPECT_EQ(r->encoding, "cdr");
  msgs::StepResponse step;
  ASSERT_TRUE(
      msgs::decode({reinterpret_cast<const std::byte*>(r->payload.data()), r->payload.size()}, step).ok());
  EXPECT_TRUE(step.success) << step.message;
  EXPECT_EQ(step.step, 5u) << "the step the stepping ends at";
  // An impulse in json: applied at step 5, the boundary the run waits at.
  ASSERT_TRUE(c.send_binary(call_frame(5, 12, "json", R"({"body":1,"jx":0.5,"jy":2.0})")));
  r = next_response(c);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->encoding, "json");
  const Json impulse = Json::parse(r->payload);
  EXPECT_EQ(impulse["success"], true) << impulse;
  EXPECT_GE(impulse["step"], 1);  // a boundary of the 5 steps, or the one the run waits at after them
  EXPECT_LE(impulse["step"], 5);
  // resume (json), then pause (cdr): `paused` updates reach the subscriber, before the reply (the
  // controller's observers run before a command's own callback).
  ASSERT_TRUE(c.send_binary(call_frame(2, 13, "json", "{}")));
  EXPECT_EQ(value_of(next_op(c, "parameterValues"), "paused")["value"], false);
  r = next_response(c);
  ASSERT_TRUE(r);
  EXPECT_EQ(Json::parse(r->payload)["success"], true);
  ASSERT_TRUE(c.send_binary(call_frame(1, 14, "cdr", cdr(msgs::TriggerRequest{}))));
  EXPECT_EQ(value_of(next_op(c, "parameterValues"), "paused")["value"], true);
  r = next_response(c);
  ASSERT_TRUE(r);
  msgs::TriggerResponse paused;
  ASSERT_TRUE(
      msgs::decode({reinterpret_cast<const std::byte*>(r->payload.data()), r->payload.size()}, paused).ok());
  EXPECT_TRUE(paused.success);
  EXPECT_NE(paused.message.find("paused at step"), std::string::npos) << paused.message;
  EXPECT_GE(s.server->stats().requests, 4u);
}

TEST(FoxgloveSteering, BadCallsGetAServiceCallFailureOrAnUnsuccessfulReply) {
  Steered s;
  ASSERT_TRUE(s.server);
  WsClient c;
  connect(c, s.server->port());
  struct Bad {
    std::string frame;
    const char* says;
  };
  for (const Bad& b : std::vector<Bad>{
           {call_frame(42, 1, "cdr", ""), "unknown service 42"},
           {call_frame(4, 2, "cdr", "\x00\x01"), "rbsim_msgs/srv/Step"},
           {call_frame(4, 3, "json", "[1]"), "not a JSON object"},
           {call_frame(4, 4, "json", R"({"steps":-1})"), "field 'steps' must be an integer"},
           {call_frame(5, 5, "json", R"({"body":0,"jz":1})"), "no field 'jz'"},
           {call_frame(5, 6, "json", R"({"body":0,"jx":"1"})"), "field 'jx' must be a number"},
           {call_frame(1, 7, "ros1", ""), "unsupported encoding"},
       }) {
    ASSERT_TRUE(c.send_binary(b.frame));
    const Json f = next_op(c, "serviceCallFailure");
    EXPECT_NE(f.value("message", "").find(b.says), std::string::npos) << f << " want " << b.says;
  }
  // Decoded but refused by the run: an unsuccessful reply naming why.
  ASSERT_TRUE(c.send_binary(call_frame(5, 8, "json", R"({"body":9})")));
  auto r = next_response(c);
  ASSERT_TRUE(r);
  EXPECT_EQ(Json::parse(r->payload)["success"], false);
  EXPECT_NE(Json::parse(r->payload)["message"].get<std::string>().find("no body 9"), std::string::npos);
  ASSERT_TRUE(c.send_binary(call_frame(4, 9, "json", R"({"steps":0})")));
  r = next_response(c);
  ASSERT_TRUE(r);
  EXPECT_NE(Json::parse(r->payload)["message"].get<std::string>().find("steps must be >= 1"),
            std::string::npos);
  // The connection still serves.
  ASSERT_TRUE(c.send_text(R"({"op":"getParameters","parameterNames":["dt"],"id":"ok"})"));
  EXPECT_EQ(next_op(c, "parameterValues")["id"], "ok");
}

TEST(FoxgloveSteering, CommandsInFlightAreBoundedPerClient) {
  ServerOptions o;
  o.max_pending_commands = 2;
  Steered s(o, false);  // no run loop: nothing is applied
  ASSERT_TRUE(s.server);
  WsClient c;
  connect(c, s.server->port());
  for (std::uint32_t call = 1; call <= 3; ++call)
    ASSERT_TRUE(c.send_binary(call_frame(1, call, "json", "{}")));
  const Json refused = next_op(c, "serviceCallFailure");
  EXPECT_EQ(refused["callId"], 3);
  EXPECT_NE(refused["message"].get<std::string>().find("too many requests in flight (2 per client)"),
            std::string::npos);
  ASSERT_TRUE(c.send_text(R"({"op":"setParameters","parameters":[{"name":"rate","value":1.0}]})"));
  EXPECT_NE(next_op(c, "status")["message"].get<std::string>().find("too many requests in flight"),
            std::string::npos);
  // Reads are not commands: still answered.
  ASSERT_TRUE(c.send_text(R"({"op":"getParameters","parameterNames":["dt"],"id":"r"})"));
  EXPECT_EQ(next_op(c, "parameterValues")["id"], "r");
  // The end of the run answers the two in flight (unsuccessfully), and the bound frees up.
  s.controller.close("the run ended");
  for (int k = 0; k < 2; ++k) {
    auto r = next_response(c);
    ASSERT_TRUE(r);
    EXPECT_EQ(Json::parse(r->payload)["success"], false);
  }
  EXPECT_EQ(s.server->stats().refused_requests, 2u);
}

TEST(FoxgloveSteering, AClientThatDoesNotReadItsRepliesIsRefusedNotBuffered) {
  ServerOptions o;
  o.max_reply_backlog_bytes = 64 << 10;
  o.max_in_flight_bytes = 64 << 10;
  Steered s(o);
  ASSERT_TRUE(s.server);
  WsClient c;
  ASSERT_EQ(c.connect(s.server->port(), {"foxglove.websocket.v1"}, 4096), 101);
  // 20,000 requests for every parameter, nothing read: the replies stop at the bound.
  const std::string get = R"({"op":"getParameters","parameterNames":[]})";
  for (int k = 0; k < 20000; ++k) {
    if (!c.send_text(get)) break;
  }
  EXPECT_TRUE([&] {
    for (int k = 0; k < 500 && s.server->stats().refused_requests == 0; ++k)
      std::this_thread::sleep_for(10ms);
    return s.server->stats().refused_requests > 0;
  }());
  const ServerStats st = s.server->stats();
  EXPECT_LT(st.requests, 20000u);
  // The run was never held up: a command from another client is answered at once.
  WsClient d;
  connect(d, s.server->port());
  ASSERT_TRUE(d.send_binary(call_frame(4, 1, "json", R"({"steps":3})")));
  auto r = next_response(d);
  ASSERT_TRUE(r);
  EXPECT_EQ(Json::parse(r->payload)["success"], true);
  // Reading, the flooder finds the one error that said so among its replies.
  int errors = 0;
  for (int k = 0; k < 20000; ++k) {
    auto f = c.read();
    if (!f) break;
    const Json j = Json::parse(f->data, nullptr, false);
    if (j.value("op", "") != "status") continue;
    ++errors;
    EXPECT_NE(j["message"].get<std::string>().find("requests refused until this client reads"),
              std::string::npos);
  }
  EXPECT_GE(errors, 1);  // one per backlog: more when reading lets a new one build up
  EXPECT_LE(static_cast<std::uint64_t>(errors), s.server->stats().refused_requests);
}

TEST(FoxgloveSteering, AnswersAfterTheServerIsGoneDoNothing) {
  Scene scene = rbsim::test::control_scene();
  control::Controller controller(scene, 3, control::RunSettings{0.0, 1, true});
  {
    ServerOptions o;
    o.address = "127.0.0.1";
    o.port = 0;
    o.steering = &controller;
    auto server = Server::start(o, {});
    ASSERT_TRUE(server);
    WsClient c;
    connect(c, server.value()->port());
    ASSERT_TRUE(c.send_binary(call_frame(1, 1, "cdr", cdr(msgs::TriggerRequest{}))));
    ASSERT_TRUE(c.send_text(R"({"op":"setParameters","parameters":[{"name":"rate","value":2.0}],"id":"x"})"));
    ASSERT_TRUE(c.send_text(R"({"op":"getParameters","parameterNames":["dt"],"id":"sync"})"));
    EXPECT_EQ(next_op(c, "parameterValues")["id"], "sync");  // both commands are queued by now
  }
  // The queued commands apply and are answered into a server that is gone, and the observer of
  // parameter updates (rate changed) does nothing either.
  control::Command resume;
  resume.kind = control::CommandKind::Resume;
  std::future<control::CommandResult> resumed = controller.submit(resume);
  Result<Driver> driver = Driver::create(scene);
  ASSERT_TRUE(driver);
  DriverOptions options;
  options.steps = 3;
  options.control = &controller;
  EXPECT_TRUE(driver.value().run_pass(options).ok());
  EXPECT_TRUE(resumed.get().successful);
  EXPECT_EQ(controller.get({"rate"})[0], msgs::ParameterValue::of_double(2.0));
}

// clientPublish: a command published on /sim/command_in applies at the next boundary.
std::string advertise_command_in(std::uint32_t id, const std::string& encoding) {
  return Json{{"op", "advertise"},
              {"channels", Json::array({{{"id", id},
                                         {"topic", "/sim/command_in"},
                                         {"encoding", encoding},
                                         {"schemaName", "rbsim_msgs/msg/Command"}}})}}
      .dump();
}
std::string published(std::uint32_t channel, const std::string& payload) {
  return "\x01" + le32(channel) + payload;
}
// Polls (bounded: 5 s) until `name` has `value` in the controller.
bool becomes(control::Controller& c, const std::string& name, const msgs::ParameterValue& value) {
  for (int k = 0; k < 500; ++k) {
    if (c.get({name})[0] == value) return true;
    std::this_thread::sleep_for(10ms);
  }
  return false;
}

TEST(FoxgloveSteering, CommandsPublishedOnCommandInApplyInCdrAndJson) {
  Steered s;
  ASSERT_TRUE(s.server);
  WsClient c;
  connect(c, s.server->port());
  ASSERT_TRUE(c.send_text(advertise_command_in(1, "json")));
  ASSERT_TRUE(c.send_text(advertise_command_in(2, "cdr")));
  ASSERT_TRUE(c.send_binary(published(
      1, R"({"kind":0,"parameters":[{"name":"forces.0.fy","value":{"type":3,"double_value":-4.0}}]})")));
  EXPECT_TRUE(becomes(s.controller, "forces.0.fy", msgs::ParameterValue::of_double(-4.0)));
  msgs::CommandMessage m;
  m.kind = msgs::CommandMessage::SetParameters;
  m.parameters = {{"forces.0.fy", msgs::ParameterValue::of_double(-1.5)}};
  ASSERT_TRUE(c.send_binary(published(2, cdr(m))));
  EXPECT_TRUE(becomes(s.controller, "forces.0.fy", msgs::ParameterValue::of_double(-1.5)));
  // The run is paused; a published resume un-pauses it.
  ASSERT_TRUE(c.send_binary(published(1, R"({"kind":2})")));
  EXPECT_TRUE(becomes(s.controller, "paused", msgs::ParameterValue::of_bool(false)));
  // Success says nothing: the next status is the refusal of an impulse on a body that is not there.
  ASSERT_TRUE(c.send_binary(published(1, R"({"kind":5,"body":99,"jx":1})")));
  const std::string refused = next_op(c, "status")["message"];
  EXPECT_NE(refused.find("clientPublish /sim/command_in: apply_impulse: "), std::string::npos) << refused;
  EXPECT_NE(refused.find("99"), std::string::npos) << refused;
  // Malformed: a status error, and the connection still serves.
  ASSERT_TRUE(c.send_binary(published(2, "\x07")));
  EXPECT_NE(next_op(c, "status")["message"].get<std::string>().find("clientPublish /sim/command_in: "),
            std::string::npos);
  ASSERT_TRUE(c.send_binary(published(1, R"({"parameters":[{"name":"nope"}]})")));
  EXPECT_NE(next_op(c, "status")["message"].get<std::string>().find("no parameter 'nope'"),
            std::string::npos);
  ASSERT_TRUE(c.send_text(R"({"op":"getParameters","parameterNames":["forces.0.fy"],"id":"ok"})"));
  EXPECT_EQ(value_of(next_op(c, "parameterValues"), "forces.0.fy")["value"], -1.5);
}

TEST(FoxgloveSteering, AFloodOfPublishedCommandsIsBoundedPerClient) {
  ServerOptions o;
  o.max_pending_commands = 4;
  Steered s(o, false);  // no run loop: nothing is applied, so every command stays in flight
  ASSERT_TRUE(s.server);
  WsClient c;
  connect(c, s.server->port());
  ASSERT_TRUE(c.send_text(advertise_command_in(1, "json")));
  for (int k = 0; k < 1000; ++k) ASSERT_TRUE(c.send_binary(published(1, R"({"kind":1})")));
  const std::string refused = next_op(c, "status")["message"];
  EXPECT_NE(refused.find("clientPublish: too many requests in flight (4 per client)"), std::string::npos)
      << refused;
  // Answered after the 996 refusals queued before it (each a status error).
  ASSERT_TRUE(c.send_text(R"({"op":"getParameters","parameterNames":["dt"],"id":"r"})"));
  int statuses = 0;
  bool answered = false;
  for (int k = 0; k < 2000 && !answered; ++k) {
    auto f = c.read();
    if (!f) break;
    const Json j = Json::parse(f->data, nullptr, false);
    statuses += j.value("op", "") == "status";
    answered = j.value("op", "") == "parameterValues" && j.value("id", "") == "r";
  }
  EXPECT_TRUE(answered);
  EXPECT_EQ(statuses, 995);  // and the one read above
  const ServerStats st = s.server->stats();
  EXPECT_EQ(st.refused_requests, 996u) << st.requests;
}

}  // namespace
}  // namespace rbsim::foxglove

namespace rbsim::foxglove {
namespace {

// Hosted services (rbsim replay's player): offered with no steering, the services capability in
// cdr and json; each call answered by its handler on the server's service thread (one that blocks
// holds up no other client's connection), a handler's error a serviceCallFailure.
TEST(FoxgloveHostedServices, AnswerCdrCallsOnTheirOwnThread) {
  std::promise<void> release;
  std::shared_future<void> released = release.get_future().share();
  ServerOptions o;
  o.port = 0;
  o.hosted_services.push_back(
      {service_spec("/player", "set_rate", "rosbag2_interfaces/srv/SetRate"),
       [](std::string_view request) -> Result<std::string> {
         msgs::SetRateRequest req;
         if (Status st =
                 msgs::decode({reinterpret_cast<const std::byte*>(request.data()), request.size()}, req);
             !st)
           return st.error();
         if (!(req.rate > 0)) return Error{"rate must be > 0"};
         return cdr(msgs::SetRateResponse{true});
       }});
  o.hosted_services.push_back({service_spec("/player", "pause", "rosbag2_interfaces/srv/Pause"),
                               [released](std::string_view) -> Result<std::string> {
                                 released.wait_for(10s);
                                 return cdr(msgs::PauseResponse{});
                               }});
  auto server = Server::start(o, {});
  ASSERT_TRUE(server) << server.error().message;
  WsClient c;
  const Json info = connect(c, server.value()->port());
  EXPECT_EQ(info["capabilities"], Json::array({"time", "services"}));
  EXPECT_EQ(info["supportedEncodings"], Json::array({"cdr", "json"}));
  const Json services = next_op(c, "advertiseServices")["services"];
  ASSERT_EQ(services.size(), 2u);
  EXPECT_EQ(services[0]["name"], "/player/set_rate");
  EXPECT_EQ(services[0]["type"], "rosbag2_interfaces/srv/SetRate");
  EXPECT_EQ(services[0]["requestSchema"], "float64 rate\n");

  ASSERT_TRUE(c.send_binary(call_frame(1, 7, "cdr", cdr(msgs::SetRateRequest{2.0}))));
  auto r = next_response(c);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->service, 1u);
  EXPECT_EQ(r->call, 7u);
  msgs::SetRateResponse set;
  ASSERT_TRUE(
      msgs::decode({reinterpret_cast<const std::byte*>(r->payload.data()), r->payload.size()}, set).ok());
  EXPECT_TRUE(set.success);
  ASSERT_TRUE(c.send_binary(call_frame(1, 8, "cdr", cdr(msgs::SetRateRequest{-1.0}))));
  Json f = next_op(c, "serviceCallFailure");
  EXPECT_EQ(f["callId"], 8);
  EXPECT_EQ(f["message"], "rate must be > 0");
  ASSERT_TRUE(c.send_binary(call_frame(1, 9, "json", R"({"rate":-1})")));
  f = next_op(c, "serviceCallFailure");
  EXPECT_EQ(f["callId"], 9);
  EXPECT_EQ(f["message"], "rate must be > 0");  // converted, then the handler's own refusal

  // A handler that blocks: the server still serves a new client meanwhile, then the answer comes.
  ASSERT_TRUE(c.send_binary(call_frame(2, 10, "cdr", cdr(msgs::PauseRequest{}))));
  WsClient other;
  EXPECT_EQ(connect(other, server.value()->port())["capabilities"], Json::array({"time", "services"}));
  release.set_value();
  r = next_response(c);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->service, 2u);
  EXPECT_EQ(r->call, 10u);
}

// A hosted call in json: converted to CDR by the request's schema (msgs::MessageDecoder::from_json),
// handed to the same CDR handler, its CDR reply converted back by the response's (to_json) and sent
// in json; a request that does not convert is refused with the converter's words, naming the field.
TEST(FoxgloveHostedServices, ConvertJsonCallsByTheServiceSchemas) {
  ServerOptions o;
  o.port = 0;
  o.hosted_services.push_back(
      {service_spec("/sim", "set_entity_state", msgs::simulation::SetEntityStateRequest::kService),
       [](std::string_view request) -> Result<std::string> {
         msgs::simulation::SetEntityStateRequest req;
         if (Status st = msgs::simulation::decode(
                 {reinterpret_cast<const std::byte*>(request.data()), request.size()}, req);
             !st)
           return st.error();
         // The reply says what arrived, so the test sees the conversion field by field.
         msgs::simulation::SetEntityStateResponse reply;
         reply.result.result = req.set_pose && !req.set_twist ? 1 : 2;
         reply.result.error_message = req.entity + " x=" + std::to_string(req.state.position.x) +
                                      " w=" + std::to_string(req.state.orientation.w) + " " +
                                      req.state.frame_id;
         Bytes out;
         msgs::simulation::encode(reply, out);
         return std::string(reinterpret_cast<const char*>(out.data()), out.size());
       }});
  auto server = Server::start(o, {});
  ASSERT_TRUE(server) << server.error().message;
  WsClient c;
  connect(c, server.value()->port());
  next_op(c, "advertiseServices");
  ASSERT_TRUE(c.send_binary(call_frame(
      1, 1, "json",
      R"({"entity":"body_2","state":{"header":{"frame_id":"world"},"pose":{"position":{"x":1.5}}},"set_pose":true})")));
  auto r = next_response(c);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->call, 1u);
  EXPECT_EQ(r->encoding, "json");
  const Json reply = Json::parse(r->payload);
  EXPECT_EQ(reply,
            Json::parse(R"({"result":{"result":1,"error_message":"body_2 x=1.500000 w=0.000000 world"}})"))
      << r->payload;
  // The same request in cdr: the same handler, the reply in cdr.
  msgs::simulation::SetEntityStateRequest req;
  req.entity = "body_2";
  req.state.frame_id = "world";
  req.state.position.x = 1.5;
  req.state.orientation.w = 0.0;
  req.set_pose = true;
  Bytes bytes;
  msgs::simulation::encode(req, bytes);
  ASSERT_TRUE(c.send_binary(
      call_frame(1, 2, "cdr", std::string(reinterpret_cast<const char*>(bytes.data()), bytes.size()))));
  r = next_response(c);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->encoding, "cdr");
  msgs::simulation::SetEntityStateResponse got;
  ASSERT_TRUE(msgs::simulation::decode(
                  {reinterpret_cast<const std::byte*>(r->payload.data()), r->payload.size()}, got)
                  .ok());
  EXPECT_EQ(got.result.result, 1);
  EXPECT_EQ(got.result.error_message, reply["result"]["error_message"]);
  // Requests that do not convert: the converter's message, with the service's name.
  ASSERT_TRUE(c.send_binary(call_frame(1, 3, "json", R"({"state":{"pose":{"position":{"x":"far"}}}})")));
  Json f = next_op(c, "serviceCallFailure");
  EXPECT_EQ(f["callId"], 3);
  EXPECT_EQ(f["message"],
            "/sim/set_entity_state: json request: state.pose.position.x: must be a number (or null for NaN)");
  ASSERT_TRUE(c.send_binary(call_frame(1, 4, "json", R"({"entity":"body_2","speed":3})")));
  f = next_op(c, "serviceCallFailure");
  EXPECT_EQ(f["message"],
            "/sim/set_entity_state: json request: speed: no such field in "
            "simulation_interfaces/srv/SetEntityState_Request");
  ASSERT_TRUE(c.send_binary(call_frame(1, 5, "json", "{not json")));
  f = next_op(c, "serviceCallFailure");
  EXPECT_NE(f["message"].get<std::string>().find("/sim/set_entity_state: json request: not JSON: "),
            std::string::npos)
      << f;
  // Still serving after them.
  ASSERT_TRUE(c.send_binary(call_frame(1, 6, "json", R"({"set_twist":true})")));
  r = next_response(c);
  ASSERT_TRUE(r);
  EXPECT_EQ(Json::parse(r->payload)["result"]["result"], 2);
}

// A hosted call that waits (rbsim node's step_simulation until its steps are done) counts against
// its client's calls in flight until answered: more are refused, not queued behind it.
TEST(FoxgloveHostedServices, CallsInFlightAreBoundedPerClient) {
  std::promise<void> release;
  std::shared_future<void> released = release.get_future().share();
  ServerOptions o;
  o.port = 0;
  o.max_pending_commands = 2;
  o.hosted_services.push_back({service_spec("/player", "pause", "rosbag2_interfaces/srv/Pause"),
                               [released](std::string_view) -> Result<std::string> {
                                 released.wait_for(10s);
                                 return cdr(msgs::PauseResponse{});
                               }});
  auto server = Server::start(o, {});
  ASSERT_TRUE(server) << server.error().message;
  WsClient c;
  connect(c, server.value()->port());
  next_op(c, "advertiseServices");
  for (std::uint32_t id = 1; id <= 3; ++id)
    ASSERT_TRUE(c.send_binary(call_frame(1, id, "cdr", cdr(msgs::PauseRequest{}))));
  const Json refused = next_op(c, "serviceCallFailure");
  EXPECT_EQ(refused["callId"], 3);
  EXPECT_NE(refused["message"].get<std::string>().find("too many requests in flight (2 per client)"),
            std::string::npos)
      << refused.dump();
  release.set_value();
  for (std::uint32_t id = 1; id <= 2; ++id) {
    const auto r = next_response(c);
    ASSERT_TRUE(r);
    EXPECT_EQ(r->call, id);
  }
  ASSERT_TRUE(c.send_binary(call_frame(1, 4, "cdr", cdr(msgs::PauseRequest{}))));  // answered: admitted again
  const auto again = next_response(c);
  ASSERT_TRUE(again);
  EXPECT_EQ(again->call, 4u);
}

}  // namespace
}  // namespace rbsim::foxglove
