// A node steered over DDS through its services (rbsim/relay.hpp's RemoteSteering).
#include <chrono>
#include <limits>

#include "rbsim/assert.hpp"
#include "rbsim/interfaces.hpp"
#include "rbsim/parameter_events.hpp"
#include "rbsim/remote_steering.hpp"
#include "rbsim/service_set.hpp"
#include "rbsim/time.hpp"

namespace rbsim::bridge {

using namespace node;

namespace {

using control::Command;
using control::CommandKind;
using control::CommandResult;

// clients_: the parameter services first, then control::control_services() in order.
enum ClientIndex : std::size_t { kList, kGet, kSet, kSetAtomically, kControls };
constexpr std::string_view kParameterServices[] = {"list_parameters", "get_parameters", "set_parameters",
                                                   "set_parameters_atomically"};
constexpr std::string_view kParameterTypes[] = {
    msgs::ListParametersRequest::kService, msgs::GetParametersRequest::kService,
    msgs::SetParametersRequest::kService, msgs::SetParametersAtomicallyRequest::kService};

// The client of the control service for `kind` (every kind but SetParameters has one).
std::size_t control_client(CommandKind kind) {
  const std::span<const control::ControlService> services = control::control_services();
  std::size_t k = 0;
  while (k + 1 < services.size() && services[k].kind != kind) ++k;
  RBSIM_ASSERT(services[k].kind == kind, "every control command but a parameter set has a service");
  return kControls + k;
}

CommandResult failed(std::string message) {
  CommandResult r;
  r.message = std::move(message);
  return r;
}

// One call: `request` encoded, sent once the node's service matched, its reply decoded as `Res`.
// Waits (bounded) for `client`'s server to match; the error names the node and the service type.
Status matched(ServiceClient& client, std::string_view service, const RemoteSteeringOptions& o) {
  if (client.server_ready() || client.wait_for_server(o.match_timeout_s)) return Ok{};
  return Error{"node " + o.node + " does not serve " + std::string(service) +
               " (is it running, on this domain?)"};
}

struct Request {
  std::size_t client = 0;  // index in clients_
  std::string service;     // its type, for messages
  Bytes body;
};

template <class Req>
Request make_request(std::size_t client, const Req& request) {
  Request r{client, std::string(Req::kService), {}};
  msgs::encode(request, r.body);
  return r;
}

// The call that carries `command`; what a ROS 2 service cannot say is refused.
Result<Request> request_for(const Command& command, const RemoteSteeringOptions& o) {
  if (command.step != Command::kNextStep) {
    return Error{"a command for a given step cannot be relayed: the node's services apply at the next step"};
  }
  switch (command.kind) {
    case CommandKind::SetParameters:
      if (command.atomic) {
        return make_request(kSetAtomically, msgs::SetParametersAtomicallyRequest{command.parameters});
      }
      return make_request(kSet, msgs::SetParametersRequest{command.parameters});
    case CommandKind::Pause:
      if (command.pause_seconds > 0.0) {
        return Error{"a timed pause cannot be relayed: node " + o.node + "'s pause service has no duration"};
      }
      [[fallthrough]];
    case CommandKind::Resume:
    case CommandKind::Reset:
      return make_request(control_client(command.kind), msgs::TriggerRequest{});
    case CommandKind::Step:
      if (command.steps < 1 || command.steps > std::numeric_limits<std::uint32_t>::max()) {
        return Error{"steps must be in [1, 2^32)"};
      }
      return make_request(control_client(CommandKind::Step),
                          msgs::StepRequest{static_cast<std::uint32_t>(command.steps)});
    case CommandKind::Impulse: {
      const control::ImpulseArgs& a = command.impulse;
      if (a.body < 0 || a.body > std::numeric_limits<std::uint32_t>::max()) {
        return Error{"body " + std::to_string(a.body) + " is not a body index"};
      }
      return make_request(control_client(CommandKind::Impulse),
                          msgs::ApplyImpulseRequest{static_cast<std::uint32_t>(a.body), a.impulse.x(),
                                                    a.impulse.y(), a.point.x(), a.point.y()});
    }
    case CommandKind::SetState:
      return Error{"set_entity_state is not relayed: call the node's set_entity_state service"};
    case CommandKind::StopStepping:
      return Error{"stop_stepping is not relayed: cancel the node's simulate_steps goal"};
    case CommandKind::Spawn:
    case CommandKind::Delete:
    case CommandKind::ResetSpawned:
    case CommandKind::LoadWorld:
    case CommandKind::UnloadWorld:
      return Error{std::string(control::to_string(command.kind)) +
                   " is not relayed: call the node's simulation_interfaces service"};
  }
  return Error{"unknown command"};
}

template <class Res>
Result<Res> decode_reply(std::span<const std::byte> reply, const RemoteSteeringOptions& o) {
  Res res;
  if (Status st = msgs::decode(reply, res); !st) {
    return with_context(
        "node " + o.node + " replied with a malformed " + std::string(Res::kService) + " response: ",
        st.error());
  }
  return res;
}

// One call, waited for: `request` sent once the node's service matched, its reply decoded.
template <class Res, class Req>
Result<Res> call(ServiceClient& client, const Req& request, const RemoteSteeringOptions& o) {
  if (Status st = matched(client, Req::kService, o); !st) return st.error();
  Bytes body;
  msgs::encode(request, body);
  Result<Bytes> reply = client.call(body, o.call_timeout_s);
  if (!reply) return with_context("node " + o.node + ": ", reply.error());
  return decode_reply<Res>(reply.value(), o);
}

// A reply of a control service as a result; `step` the boundary it applied at when the reply says.
template <class Res>
CommandResult control_result(const Result<Res>& reply) {
  if (!reply) return failed(reply.error().message);
  CommandResult r;
  r.successful = reply->success;
  r.message = reply->message;
  if constexpr (requires { reply->step; }) {
    if (reply->step <= static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max())) {
      // A step reply names where the stepping ends, an impulse reply the boundary it applied at.
      (std::is_same_v<Res, msgs::StepResponse> ? r.ends_at : r.step) = static_cast<std::int64_t>(reply->step);
    }
  }
  return r;
}

// The node's reply to the call that carried `command`, as its result.
CommandResult result_of(const Command& command, std::span<const std::byte> reply,
                        const RemoteSteeringOptions& o) {
  switch (command.kind) {
    case CommandKind::SetParameters: {
      CommandResult r;
      if (command.atomic) {
        auto res = decode_reply<msgs::SetParametersAtomicallyResponse>(reply, o);
        if (!res) return failed(res.error().message);
        r.results = {res->result};
        r.successful = res->result.successful;
        r.message = res->result.reason;
        if (r.successful) r.changed = command.parameters;
        return r;
      }
      auto res = decode_reply<msgs::SetParametersResponse>(reply, o);
      if (!res) return failed(res.error().message);
      if (res->results.size() != command.parameters.size()) {
        return failed("node " + o.node + " answered " + std::to_string(res->results.size()) +
                      " results for " + std::to_string(command.parameters.size()) + " parameters");
      }
      r.results = res->results;
      r.successful = true;
      for (std::size_t k = 0; k < r.results.size(); ++k) {
        if (r.results[k].successful) {
          r.changed.push_back(command.parameters[k]);
        } else if (r.successful) {
          r.successful = false;
          r.message = r.results[k].reason;
        }
      }
      return r;
    }
    case CommandKind::Pause:
    case CommandKind::Resume:
    case CommandKind::Reset:
      return control_result(decode_reply<msgs::TriggerResponse>(reply, o));
    case CommandKind::Step:
      return control_result(decode_reply<msgs::StepResponse>(reply, o));
    case CommandKind::Impulse:
      return control_result(decode_reply<msgs::ApplyImpulseResponse>(reply, o));
    case CommandKind::SetState:
    case CommandKind::StopStepping:
    case CommandKind::Spawn:
    case CommandKind::Delete:
    case CommandKind::ResetSpawned:
    case CommandKind::LoadWorld:
    case CommandKind::UnloadWorld:
      break;  // never sent (make_request refuses them)
  }
  return failed("unknown command");
}

}  // namespace

Result<std::unique_ptr<RemoteSteering>> RemoteSteering::create(const Participant& participant,
                                                               const RemoteSteeringOptions& options) {
  std::unique_ptr<RemoteSteering> s(new RemoteSteering());
  s->options_ = options;
  auto add = [&](std::string_view name, std::string_view type) -> Status {
    ClientOptions co;
    co.in_graph = true;  // ros2 node info lists the bridge's clients
    Result<ServiceClient> c =
        ServiceClient::create(participant, options.node + "/" + std::string(name), type, co);
    if (!c) return c.error();
    s->clients_.push_back(std::move(c.value()));
    return Ok{};
  };
  for (std::size_t k = 0; k < std::size(kParameterServices); ++k) {
    if (Status st = add(kParameterServices[k], kParameterTypes[k]); !st) return st.error();
  }
  for (const control::ControlService& c : control::control_services()) {
    if (Status st = add(c.name, c.type); !st) return st.error();
  }
  auto events = Subscription::create(participant, parameter_events_topic(), parameter_events_qos());
  if (!events) return events.error();
  s->events_.emplace(std::move(events.value()));
  RemoteSteering* raw = s.get();
  s->thread_ = std::thread([raw] { raw->run(); });
  return s;
}

RemoteSteering::~RemoteSteering() {
  {
    const std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_one();
  if (thread_.joinable()) thread_.join();
  for (Pending& p : queue_) p.done(failed("the bridge stopped"));
}

Status RemoteSteering::refresh() {
  msgs::ListParametersRequest list;  // every name, any depth
  Result<msgs::ListParametersResponse> listed =
      call<msgs::ListParametersResponse>(client(kList), list, options_);
  if (!listed) return listed.error();
  msgs::GetParametersRequest get{listed->result.names};
  Result<msgs::GetParametersResponse> got = call<msgs::GetParametersResponse>(client(kGet), get, options_);
  if (!got) return got.error();
  if (got->values.size() != get.names.size()) {
    return Error{"node " + options_.node + " answered " + std::to_string(got->values.size()) +
                 " values for " + std::to_string(get.names.size()) + " parameters"};
  }
  const std::lock_guard lock(mutex_);
  names_ = std::move(get.names);
  values_.clear();
  for (std::size_t k = 0; k < names_.size(); ++k) values_[names_[k]] = std::move(got->values[k]);
  return Ok{};
}

void RemoteSteering::submit(Command command, std::function<void(const CommandResult&)> done) {
  {
    const std::lock_guard lock(mutex_);
    if (!stopping_) {
      queue_.push_back({std::move(command), std::move(done)});
      wake_.notify_one();
      return;
    }
  }
  done(failed("the bridge stopped"));
}

std::vector<std::optional<msgs::ParameterValue>> RemoteSteering::get(
    const std::vector<std::string>& names) const {
  const std::lock_guard lock(mutex_);
  std::vector<std::optional<msgs::ParameterValue>> out;
  for (const std::string& n : names) {
    const auto it = values_.find(n);
    out.push_back(it == values_.end() ? std::nullopt : std::optional(it->second));
  }
  return out;
}

std::vector<msgs::ParameterType> RemoteSteering::types(const std::vector<std::string>& names) const {
  const std::lock_guard lock(mutex_);
  std::vector<msgs::ParameterType> out;
  for (const std::string& n : names) {
    const auto it = values_.find(n);
    out.push_back(it == values_.end() ? msgs::ParameterType::NotSet : it->second.type);
  }
  return out;
}

std::vector<std::string> RemoteSteering::names() const {
  const std::lock_guard lock(mutex_);
  return names_;
}

void RemoteSteering::on_command(std::function<void(const Command&, const CommandResult&)> observer) {
  const std::lock_guard lock(observers_mutex_);
  observers_.push_back(std::move(observer));
}

std::uint64_t RemoteSteering::calls() const {
  const std::lock_guard lock(mutex_);
  return calls_;
}

// The thread: every submitted command's request sent at once, in submission order (a call the
// node holds back, such as an impulse while paused, must not hold up the step that releases it),
// replies matched to their calls by sequence number, parameter events as they come; it polls
// every few milliseconds while calls are out.
void RemoteSteering::run() {
  std::vector<InFlight> out;
  std::vector<Pending> fresh;
  Bytes reply;
  while (true) {
    {
      std::unique_lock lock(mutex_);
      wake_.wait_for(lock, std::chrono::milliseconds(out.empty() ? 20 : 2),
                     [this] { return stopping_ || !queue_.empty(); });
      if (stopping_) break;
      while (!queue_.empty()) {
        fresh.push_back(std::move(queue_.front()));
        queue_.pop_front();
        ++calls_;
      }
    }
    for (Pending& p : fresh) send(std::move(p), out);
    fresh.clear();
    collect(out, reply);
    take_events();
  }
  for (InFlight& f : out) f.done(failed("the bridge stopped before node " + options_.node + " replied"));
}

void RemoteSteering::send(Pending pending, std::vector<InFlight>& out) {
  Result<Request> request = request_for(pending.command, options_);
  if (!request) {
    pending.done(failed(request.error().message));
    return;
  }
  ServiceClient& c = client(request->client);
  if (Status st = matched(c, request->service, options_); !st) {
    pending.done(failed(st.error().message));
    return;
  }
  Result<std::int64_t> seq = c.send(request->body);
  if (!seq) {
    pending.done(failed("node " + options_.node + ": " + seq.error().message));
    return;
  }
  const auto deadline = std::chrono::steady_clock::now() +
                        std::chrono::nanoseconds(seconds_to_ns_clamped(options_.call_timeout_s));
  out.push_back(
      {std::move(pending.command), std::move(pending.done), request->client, seq.value(), deadline});
}

// Answers the calls whose replies came, and those past their deadline.
void RemoteSteering::collect(std::vector<InFlight>& out, Bytes& reply) {
  for (std::size_t index = kSet; index < clients_.size(); ++index) {
    RequestHeader header;
    while (client(index).take_reply(header, reply)) {
      for (auto it = out.begin(); it != out.end(); ++it) {
        if (it->client != index || it->seq != header.seq) continue;
        it->done(result_of(it->command, reply, options_));
        out.erase(it);
        break;
      }
    }
  }
  const auto now = std::chrono::steady_clock::now();
  for (auto it = out.begin(); it != out.end();) {
    if (it->deadline > now) {
      ++it;
      continue;
    }
    it->done(failed("node " + options_.node + " did not reply within " +
                    std::to_string(options_.call_timeout_s) + " s"));
    it = out.erase(it);
  }
}

// The node's /parameter_events (others' events and undecodable samples are skipped): the table
// follows them, and each reaches the observers as the parameters it changed.
void RemoteSteering::take_events() {
  while (events_->take(event_sample_)) {
    msgs::ParameterEvent event;
    if (!msgs::decode(event_sample_.cdr, event) || event.node != options_.node) continue;
    CommandResult r;
    r.successful = true;
    r.changed = std::move(event.new_parameters);
    r.changed.insert(r.changed.end(), event.changed_parameters.begin(), event.changed_parameters.end());
    {
      const std::lock_guard lock(mutex_);
      for (const msgs::Parameter& p : r.changed) {
        if (values_.count(p.name) == 0) names_.push_back(p.name);
        values_[p.name] = p.value;
      }
    }
    Command c;
    c.kind = CommandKind::SetParameters;
    c.source = "parameter event";
    const std::lock_guard lock(observers_mutex_);
    for (const auto& observer : observers_) observer(c, r);
  }
}

}  // namespace rbsim::bridge
