// The node's parameter and control services (rbsim/node_services.hpp).
#include "rbsim/node_services.hpp"

#include <atomic>
#include <chrono>
#include <cmath>
#include <future>
#include <vector>

#include "rbsim/interfaces.hpp"
#include "rbsim/parameter_events.hpp"
#include "rbsim/print.hpp"
#include "rbsim/service.hpp"
#include "rbsim/service_set.hpp"
#include "simulate_steps.hpp"
#include "simulation_services.hpp"

namespace rbsim::node {

namespace {

using control::Command;
using control::CommandKind;
using control::CommandResult;

constexpr std::size_t kBudgetPerServer = 8;  // requests one server handles before the next one's turn

// /<ns>/commands: every command reaches a late joiner (a recorder started after the first
// command), reliable, transient local, keep all.
QosSpec commands_qos() {
  QosSpec q;
  q.transient_local = true;
  q.keep_all = true;
  return q;
}

using ServiceEntry = std::tuple<std::string, std::string, ServiceServer::Handler>;

// rclcpp's ~/get_type_description, answered from the participant's node type cache: the types of
// the endpoints the node created, this service's own among them, as rcl's cache holds them.
// Without a participant (catalogue()), listed only: its handler answers nothing.
void add_type_description(const Participant* participant, std::vector<ServiceEntry>& out) {
  using msgs::GetTypeDescriptionRequest;
  using msgs::GetTypeDescriptionResponse;
  if (participant == nullptr) {
    out.emplace_back("get_type_description", std::string(GetTypeDescriptionRequest::kService),
                     [](const RequestHeader&, std::span<const std::byte>, Bytes&) { return false; });
    return;
  }
  out.emplace_back(
      "get_type_description", std::string(GetTypeDescriptionRequest::kService),
      typed_handler<GetTypeDescriptionRequest, GetTypeDescriptionResponse>(
          [types = participant->types()](const RequestHeader&, const GetTypeDescriptionRequest& req) {
            return describe_node_type(*types, req);
          },
          [](const Error& e) {
            GetTypeDescriptionResponse res;
            res.failure_reason = e.message;
            return std::optional<GetTypeDescriptionResponse>(std::move(res));
          }));
}

// The source apply() records a command with, when a handler runs for a front end other than DDS
// (simulation_handlers()): set on the calling thread for the call's length, which is where the
// handler submits its commands.
thread_local const std::string* t_source = nullptr;

// The parameter that switches service introspection (ROS 2's introspection demos' name).
constexpr std::string_view kIntrospectionParameter = "service_configure_introspection";

}  // namespace

struct NodeServices::Impl {
  const Participant* participant;  // null for catalogue()'s
  control::Controller& controller;
  NodeServicesOptions options;
  std::optional<Publisher> events;
  std::optional<Publisher> commands;  // /<ns>/commands
  Bytes command_cdr;                  // the run loop's thread only
  std::uint64_t next_sequence = 0;    // the run loop's thread only
  Bytes event_cdr;
  std::atomic<std::uint64_t> event_count{0};
  std::atomic<std::uint64_t> command_count{0};
  ResourceFolders spawnables;                      // options.spawnables, opened by create()
  ResourceFolders worlds;                          // options.worlds, the same
  std::unique_ptr<SimulationServices> simulation;  // simulation_interfaces' services
  std::unique_ptr<SimulateSteps> simulate_steps;   // and its action
  // simulation_interfaces' services in collect()'s list: [first, end); their entries (handlers
  // copied) kept by create() for simulation_handlers().
  std::size_t simulation_first = 0, simulation_end = 0;
  std::vector<ServiceEntry> simulation_entries;
  ServiceSet services;  // last: stopped first, before the members its handlers use go

  Impl(const Participant* p, control::Controller& c, NodeServicesOptions o)
      : participant(p), controller(c), options(std::move(o)) {}

  // Every service of the node with its handler, in the order served: the one list, for create()
  // and catalogue().
  std::vector<std::tuple<std::string, std::string, ServiceServer::Handler>> collect() {
    std::vector<std::tuple<std::string, std::string, ServiceServer::Handler>> all;
    add_controls(all);
    add_parameters(all);
    simulation = std::make_unique<SimulationServices>(
        controller, [this](Command c) { return apply(std::move(c)); },
        [this](std::vector<Command> c) { return apply_all(std::move(c)); }, options.apply_timeout_s,
        spawnables, worlds, options.quit);
    simulation_first = all.size();
    simulation->add(all);
    simulation_end = all.size();
    if (options.start_type_description_service) add_type_description(participant, all);
    return all;
  }

  // Submits `command` and waits (bounded) for the boundary that applies it.
  CommandResult apply(Command command) {
    command.source = t_source != nullptr ? *t_source : "ros2 service";
    std::future<CommandResult> done = controller.submit(std::move(command));
    if (done.wait_for(std::chrono::duration<double>(options.apply_timeout_s)) != std::future_status::ready) {
      CommandResult r;
      r.message = "not applied within " + std::to_string(options.apply_timeout_s) + " s";
      return r;
    }
    return done.get();
  }

  // Submits `batch` together (Controller::submit_all: they apply at one boundary) and waits
  // (bounded, once for all) for their results.
  std::vector<CommandResult> apply_all(std::vector<Command> batch) {
    for (Command& c : batch) c.source = t_source != nullptr ? *t_source : "ros2 service";
    std::vector<std::future<CommandResult>> done = controller.submit_all(std::move(batch));
    std::vector<CommandResult> out;
    bool late = false;  // one wait for all: after a timeout, what is not ready at once is late too
    for (std::future<CommandResult>& f : done) {
      const double wait = late ? 0.0 : options.apply_timeout_s;
      if (f.wait_for(std::chrono::duration<double>(wait)) != std::future_status::ready) {
        late = true;
        CommandResult r;
        r.message = "not applied within " + std::to_string(options.apply_timeout_s) + " s";
        out.push_back(std::move(r));
        continue;
      }
      out.push_back(f.get());
    }
    return out;
  }

  // The control services through the control module's one mapping (control::control_services()).
  void add_controls(std::vector<std::tuple<std::string, std::string, ServiceServer::Handler>>& out) {
    using namespace msgs;
    for (const control::ControlService& s : control::control_services()) {
      ServiceServer::Handler h;
      if (s.kind == CommandKind::Step) {
        h = typed_handler<StepRequest, StepResponse>(
            [this](const RequestHeader&, const StepRequest& req) {
              return control::step_response(apply(control::command_for(req)));
            },
            [](const Error& e) {
              return std::optional<StepResponse>(StepResponse{false, e.message, 0});
            });
      } else if (s.kind == CommandKind::Impulse) {
        h = typed_handler<ApplyImpulseRequest, ApplyImpulseResponse>(
            [this](const RequestHeader&, const ApplyImpulseRequest& req) {
              return control::impulse_response(apply(control::command_for(req)));
            },
            [](const Error& e) {
              return std::optional<ApplyImpulseResponse>(ApplyImpulseResponse{false, e.message, 0});
            });
      } else {
        h = typed_handler<TriggerRequest, TriggerResponse>(
            [this, kind = s.kind](const RequestHeader&, const TriggerRequest& req) {
              return control::trigger_response(apply(control::command_for(kind, req)));
            },
            [](const Error& e) {
              return std::optional<TriggerResponse>(TriggerResponse{false, e.message});
            });
      }
      out.emplace_back(std::string(s.name), std::string(s.type), std::move(h));
    }
  }

  // rclcpp's parameter services: reads answer from the table as of the last boundary; a read
  // naming an unknown parameter answers an empty list, as rclcpp's do; a malformed request gets no
  // reply (these responses have no field to say so).
  void add_parameters(std::vector<std::tuple<std::string, std::string, ServiceServer::Handler>>& out) {
    using namespace msgs;
    out.emplace_back("list_parameters", std::string(ListParametersRequest::kService),
                     typed_handler<ListParametersRequest, ListParametersResponse>(
                         [this](const RequestHeader&, const ListParametersRequest& req) {
                           return ListParametersResponse{controller.list(req.prefixes, req.depth)};
                         },
                         [](const Error&) { return std::optional<ListParametersResponse>(); }));
    out.emplace_back("get_parameters", std::string(GetParametersRequest::kService),
                     typed_handler<GetParametersRequest, GetParametersResponse>(
                         [this](const RequestHeader&, const GetParametersRequest& req) {
                           GetParametersResponse res;
                           for (auto& v : controller.get(req.names)) {
                             if (!v) return GetParametersResponse{};
                             res.values.push_back(std::move(*v));
                           }
                           return res;
                         },
                         [](const Error&) { return std::optional<GetParametersResponse>(); }));
    out.emplace_back("describe_parameters", std::string(DescribeParametersRequest::kService),
                     typed_handler<DescribeParametersRequest, DescribeParametersResponse>(
                         [this](const RequestHeader&, const DescribeParametersRequest& req) {
                           DescribeParametersResponse res;
                           for (auto& d : controller.describe(req.names)) {
                             if (!d) return DescribeParametersResponse{};
                             res.descriptors.push_back(std::move(*d));
                           }
                           return res;
                         },
                         [](const Error&) { return std::optional<DescribeParametersResponse>(); }));
    out.emplace_back("get_parameter_types", std::string(GetParameterTypesRequest::kService),
                     typed_handler<GetParameterTypesRequest, GetParameterTypesResponse>(
                         [this](const RequestHeader&, const GetParameterTypesRequest& req) {
                           GetParameterTypesResponse res;
                           for (ParameterType t : controller.types(req.names))
                             res.types.push_back(static_cast<std::uint8_t>(t));
                           return res;
                         },
                         [](const Error&) { return std::optional<GetParameterTypesResponse>(); }));
    out.emplace_back("set_parameters", std::string(SetParametersRequest::kService),
                     typed_handler<SetParametersRequest, SetParametersResponse>(
                         [this](const RequestHeader&, const SetParametersRequest& req) {
                           Command c;
                           c.kind = CommandKind::SetParameters;
                           c.atomic = false;
                           c.parameters = req.parameters;
                           CommandResult r = apply(std::move(c));
                           if (r.results.size() != req.parameters.size()) {  // never applied
                             r.results.assign(req.parameters.size(), SetParametersResult{false, r.message});
                           }
                           return SetParametersResponse{std::move(r.results)};
                         },
                         [](const Error&) { return std::optional<SetParametersResponse>(); }));
    out.emplace_back("set_parameters_atomically", std::string(SetParametersAtomicallyRequest::kService),
                     typed_handler<SetParametersAtomicallyRequest, SetParametersAtomicallyResponse>(
                         [this](const RequestHeader&, const SetParametersAtomicallyRequest& req) {
                           Command c;
                           c.kind = CommandKind::SetParameters;
                           c.atomic = true;
                           c.parameters = req.parameters;
                           const CommandResult r = apply(std::move(c));
                           SetParametersResult result{r.successful, r.successful ? std::string{} : r.message};
                           if (!r.results.empty() && !r.results.front().successful)
                             result = r.results.front();
                           return SetParametersAtomicallyResponse{result};
                         },
                         [](const Error&) { return std::optional<SetParametersAtomicallyResponse>(); }));
  }
};

namespace {
// The node's services as create() serves them, names and types, [first, end) of them: the one
// list, its handlers made and dropped uncalled (they only need a controller to refer to, and no
// participant is touched). `simulation` keeps simulation_interfaces' alone.
std::vector<NodeServices::Served> served(bool simulation) {
  const Scene scene;
  control::Controller controller(scene, 0, control::RunSettings{});
  NodeServices::Impl impl(nullptr, controller, {});
  std::vector<ServiceEntry> all = impl.collect();
  const std::size_t first = simulation ? impl.simulation_first : 0;
  const std::size_t end = simulation ? impl.simulation_end : all.size();
  std::vector<NodeServices::Served> out;
  for (std::size_t i = first; i < end; ++i) out.push_back({std::get<0>(all[i]), std::get<1>(all[i])});
  return out;
}
}  // namespace

std::vector<NodeServices::Served> NodeServices::catalogue() {
  return served(false);
}

std::vector<NodeServices::Served> NodeServices::simulation_catalogue() {
  return served(true);
}

std::vector<NodeServices::Handled> NodeServices::simulation_handlers(std::string source) const {
  auto shared = std::make_shared<const std::string>(std::move(source));
  std::vector<Handled> out;
  for (const ServiceEntry& e : impl_->simulation_entries) {
    out.push_back({std::get<0>(e), std::get<1>(e),
                   [shared, handler = std::get<2>(e)](const RequestHeader& header,
                                                      std::span<const std::byte> request, Bytes& reply) {
                     const std::string* outer = t_source;
                     t_source = shared.get();
                     const bool answered = handler(header, request, reply);
                     t_source = outer;
                     return answered;
                   }});
  }
  return out;
}

NodeServices::NodeServices(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

NodeServices::~NodeServices() {
  impl_->services.stop();
}

Result<std::unique_ptr<NodeServices>> NodeServices::create(const Participant& participant,
                                                           control::Controller& controller,
                                                           const NodeServicesOptions& options) {
  auto impl = std::make_unique<Impl>(&participant, controller, options);
  Result<ResourceFolders> spawnables = ResourceFolders::open(options.spawnables, "spawnables folder");
  if (!spawnables) return spawnables.error();
  impl->spawnables = std::move(spawnables.value());
  Result<ResourceFolders> worlds = ResourceFolders::open(options.worlds, "worlds folder");
  if (!worlds) return worlds.error();
  impl->worlds = std::move(worlds.value());
  std::vector<std::tuple<std::string, std::string, ServiceServer::Handler>> services = impl->collect();
  impl->simulation_entries.assign(services.begin() + static_cast<std::ptrdiff_t>(impl->simulation_first),
                                  services.begin() + static_cast<std::ptrdiff_t>(impl->simulation_end));
  for (auto& [name, type, handler] : services) {
    if (Status st = impl->services.add(participant, options.node, name, type, std::move(handler),
                                       SimulationServices::max_request_bytes(name));
        !st)
      return st.error();
  }
  auto action = SimulateSteps::create(participant, options.node, controller);
  if (!action) return action.error();
  impl->simulate_steps = std::move(action.value());
  auto events = Publisher::create(participant, parameter_events_topic(), parameter_events_qos());
  if (!events) return events.error();
  impl->events.emplace(std::move(events.value()));
  const std::string commands_topic = options.node + "/" + std::string(msgs::CommandMessage::kSuffix);
  auto commands = Publisher::create(
      participant, RawTopic{commands_topic, std::string(msgs::CommandMessage::kType)}, commands_qos());
  if (!commands) return commands.error();
  impl->commands.emplace(std::move(commands.value()));
  if (Status st = impl->services.configure_introspection(participant, options.introspection); !st)
    return st.error();
  impl->services.start(kBudgetPerServer);
  return std::unique_ptr<NodeServices>(new NodeServices(std::move(impl)));
}

void NodeServices::command_applied(const Command& command, const CommandResult& result) {
  // Every command, applied or refused, as data on /<ns>/commands, numbered without gaps.
  impl_->command_cdr.clear();
  msgs::encode(
      control::to_message(command, result, impl_->next_sequence++, impl_->controller.world_info().dt),
      impl_->command_cdr);
  if (impl_->commands->publish(impl_->command_cdr)) ++impl_->command_count;
  for (const msgs::Parameter& p : result.changed) {
    if (p.name != kIntrospectionParameter) continue;
    const std::optional<IntrospectionState> state = msgs::parse_introspection_state(p.value.string_value);
    if (!state) continue;  // the table accepts the three words only
    if (Status st = impl_->services.configure_introspection(*impl_->participant, *state); !st)
      RBSIM_LOG(Warn, "rbsim node: warning: service introspection stays %s: %s\n",
                std::string(msgs::to_string(impl_->services.introspection())).c_str(),
                st.error().message.c_str());
  }
  if (result.changed.empty() || result.step < 0) return;
  msgs::ParameterEvent event;
  event.node = impl_->options.node;
  event.stamp = msgs::sim_time(result.step, impl_->controller.world_info().dt);
  event.changed_parameters = result.changed;
  impl_->event_cdr.clear();
  msgs::encode(event, impl_->event_cdr);
  if (impl_->events->publish(impl_->event_cdr)) ++impl_->event_count;
}

std::span<const std::byte> NodeServices::last_command() const {
  return impl_->command_cdr;
}

NodeServiceCounters NodeServices::counters() const {
  NodeServiceCounters c;
  const auto add = [&c](const ServiceStats& st, std::uint64_t unanswered) {
    c.received += st.received;
    c.calls += st.answered;
    c.dropped += st.dropped_full + st.dropped_large + st.malformed + st.client_gone + st.client_unmatched +
                 unanswered + st.write_failed;
  };
  for (const ServiceStats& st : impl_->services.stats()) add(st, st.unanswered);
  // The action's handlers leave a get_result unanswered to answer it later: its own malformed
  // count is what went unanswered for good.
  const ActionStats action = impl_->simulate_steps->stats();
  add(action.send_goal, 0);
  add(action.cancel_goal, 0);
  add(action.get_result, 0);
  c.dropped += action.malformed;
  c.events = impl_->event_count.load();
  c.commands = impl_->command_count.load();
  c.service_events = impl_->services.events_published();
  return c;
}

}  // namespace rbsim::node
