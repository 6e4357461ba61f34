// rbsim bridge: the DDS topics of any rbsim node relayed to Foxglove over its WebSocket protocol,
// and Foxglove's parameter requests and service calls relayed to the node's services (what
// foxglove_bridge does for ROS 2, with no ROS install).
#include <cstdio>
#include <memory>

#include "cli_util.hpp"
#include "commands.hpp"
#include "rbsim/dds.hpp"
#include "rbsim/forwarded_service.hpp"
#include "rbsim/node_services.hpp"
#include "rbsim/relay.hpp"
#include "rbsim/remote_steering.hpp"
#include "rbsim/rosout.hpp"
#include "validators.hpp"

namespace rbsim::cli {

namespace {
struct BridgeArgs {
  FoxgloveArgs foxglove;  // --foxglove [ADDR:]PORT and its access options
  std::string ns = "rbsim";
  std::uint32_t domain = node::kDomainFromEnvironment;  // add_domain_option sets it
  node::NodeName node{"/", "rbsim_bridge"};             // as foxglove_bridge names its node
  bool quiet = false;
};

// The simulated time a sample carries (ns): the scene description's stamp, a per-step message's
// header stamp or clock; nullopt when it has none.
std::optional<std::uint64_t> sim_time(const msgs::TopicSpec& spec, std::span<const std::byte> cdr) {
  std::optional<msgs::Time> stamp;
  if (spec.id == msgs::TopicId::SceneDescription) {
    if (auto scene = msgs::decode_scene(cdr)) stamp = scene.value().stamp;
  } else {
    stamp = msgs::decode_stamp(spec.id, cdr);
  }
  if (!stamp || stamp->sec < 0) return std::nullopt;
  return static_cast<std::uint64_t>(stamp->sec) * 1'000'000'000ull + stamp->nanosec;
}

int bridge_command(const BridgeArgs& a) {
  // Ctrl-C and SIGTERM only raise a flag from here on, before anything a stop must undo exists
  // (a participant, a listener, an output file): a stop at any stage of start-up ends cleanly.
  install_stop_handlers();
  auto participant = node::create_dds_participant(a.domain, a.node);
  if (!participant) return fail("bridge", participant.error().message);
  auto rosout = node::Rosout::create(participant.value());
  if (!rosout) return fail("bridge", rosout.error().message);
  std::vector<foxglove::ChannelId> ids;
  msgs::TopicSet all;
  all.set();  // every topic a node may publish: the viewer chooses what to subscribe to
  auto channels = foxglove::ros2_channels(all, a.ns, &ids);
  if (!channels) return fail("bridge", channels.error().message);
  auto relay = bridge::Relay::create(participant.value(), a.ns);
  if (!relay) return fail("bridge", relay.error().message);
  // The steered node is the one whose topics are relayed: /<namespace> (as rbsim node names itself).
  const Result<node::NodeName> target = node::parse_node_name(a.ns);
  if (!target) return fail("bridge", target.error().message, 2);
  bridge::RemoteSteeringOptions steer;
  steer.node = target->fully_qualified();
  auto steering = bridge::RemoteSteering::create(participant.value(), steer);
  if (!steering) return fail("bridge", steering.error().message);
  // simulation_interfaces' services, the node's own list of them: each call forwarded as raw CDR
  // to the node's DDS service (bounded; a node that does not answer fails the call, saying so).
  std::vector<foxglove::HostedService> hosted;
  for (const node::NodeServices::Served& s : node::NodeServices::simulation_catalogue()) {
    auto forward = bridge::ForwardedService::create(participant.value(), steer.node, s.name, s.type);
    if (!forward) return fail("bridge", forward.error().message);
    hosted.push_back(
        hosted_service(steer.node, s.name, s.type,
                       [f = std::shared_ptr<bridge::ForwardedService>(std::move(forward.value()))](
                           std::span<const std::byte> request) { return f->call(request); }));
  }
  auto started = start_foxglove("rbsim bridge", a.foxglove, std::move(channels.value()),
                                steering.value().get(), steer.node, std::move(hosted));
  if (!started) return fail("bridge", started.error().message, foxglove_exit_status(started.error()));
  foxglove::Server& server = *started.value();
  if (!a.quiet) {
    RBSIM_LOG(Info, "rbsim bridge: relaying /%s/* and /clock on %s (Ctrl-C stops)\n", a.ns.c_str(),
              participant.value().description().c_str());
  }
  std::uint64_t last_time = 0, scenes = 0;
  const bridge::Relay::OnSample on_sample = [&](const msgs::TopicSpec& spec, std::span<const std::byte> cdr) {
    const std::optional<std::uint64_t> t = sim_time(spec, cdr);
    if (spec.id == msgs::TopicId::SceneDescription) {
      // A scene (re)started: its node's parameters (read before the new session, which hands them
      // to the viewers), and a new session, so viewers drop what they showed of the last one. A
      // source without services (rbsim replay) costs a bounded wait and a line.
      if (Status st = steering.value()->refresh(); !st && !a.quiet) {
        RBSIM_LOG(Warn, "rbsim bridge: warning: no parameters or controls to relay: %s\n",
                  st.error().message.c_str());
      }
      server.new_session();
      last_time = 0;
      ++scenes;
    } else if (t && *t > last_time) {
      server.time(*t);
      last_time = *t;
    }
    server.publish(ids[static_cast<std::size_t>(spec.id)], t.value_or(last_time), cdr);
  };
  while (!stop_requested()) {
    auto polled = relay.value()->poll(100'000'000, on_sample);
    if (!polled) return fail("bridge", polled.error().message);
  }
  if (!a.quiet) {
    RBSIM_LOG(
        Info,
        "rbsim bridge: stopped after %llu samples (%llu scene descriptions, %llu lost in DDS), %llu commands "
        "relayed to %s; %s\n",
        static_cast<unsigned long long>(relay.value()->received()), static_cast<unsigned long long>(scenes),
        static_cast<unsigned long long>(relay.value()->lost()),
        static_cast<unsigned long long>(steering.value()->calls()), steer.node.c_str(),
        foxglove_summary(server).c_str());
  }
  return 0;
}
}  // namespace

Subcommand add_bridge_command(CLI::App& parent) {
  auto a = std::make_shared<BridgeArgs>();
  CLI::App* app = parent.add_subcommand(
      "bridge",
      "Relay the DDS topics of a running rbsim node to Foxglove (its WebSocket protocol; no ROS needed)");
  add_foxglove_option(app, a->foxglove, true);
  add_domain_option(app, a->domain);
  add_node_name_option(app, a->node);
  app->add_option("--namespace", a->ns, "ROS namespace of the node's topics")
      ->check(ros_namespace())
      ->default_str("rbsim");
  app->add_flag("-q,--quiet", a->quiet, "No start and end lines (the listening line is always printed)");
  app->footer(
      "Subscribes to every rbsim topic under /<namespace> and /clock (the scene description transient local, "
      "so a "
      "bridge started after the node still gets it; the per-step topics keep last 256, so a bridge never "
      "slows the "
      "node) and serves them as Foxglove channels (encoding cdr, ros2msg schemas, log time = simulated "
      "time). "
      "Every scene description that arrives (a node started, or a --loop pass) starts a new session.\n"
      "Steering: Foxglove's Parameters panel, its service calls (pause, resume, reset, step, apply_impulse) "
      "and "
      "commands published on /<namespace>/command_in reach the node /<namespace> through its ROS 2 services "
      "(rcl_interfaces' set_parameters, rbsim's controls), as any ROS 2 client's would: the node applies "
      "them "
      "at its next step and records them on /<namespace>/commands (source \"ros2 service\"). "
      "simulation_interfaces' services (get_simulation_state, step_simulation, get_entity_state, ...) are "
      "offered too, each call forwarded in cdr to the node's service of that name (12 s at most). The "
      "parameter "
      "table is read from the node when its scene description arrives and follows /parameter_events. A "
      "command for a given step or a timed pause cannot be relayed (the services have neither). Ctrl-C "
      "stops.\n"
      "Exit status: 0 stopped by Ctrl-C/SIGTERM, 1 error (DDS failure, --foxglove port in use), 2 usage "
      "error.");
  return {app, [a] { return bridge_command(*a); }};
}

}  // namespace rbsim::cli
