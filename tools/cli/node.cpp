// rbsim node: run a scene and stream it over DDS with ROS 2 conventions.
#include <malloc.h>

#include <chrono>
#include <cstdio>
#include <memory>

#include "cli_util.hpp"
#include "commands.hpp"
#include "rbsim/control.hpp"
#include "rbsim/dds.hpp"
#include "rbsim/dds_sink.hpp"
#include "rbsim/node_services.hpp"
#include "rbsim/ros_args.hpp"
#include "rbsim/rosout.hpp"
#include "rbsim/run.hpp"
#include "validators.hpp"

namespace rbsim::cli {

namespace {
struct NodeArgs {
  std::string scene;
  node::NodeOptions node;
  std::optional<double> duration;
  bool loop = false;
  bool allow_nonfinite = false;
  std::int32_t wait_for = 0;
  bool quiet = false;
  std::string topics;
  FoxgloveArgs foxglove;   // --foxglove [ADDR:]PORT and its access options
  std::string spawnables;  // --spawnables DIR
  std::string worlds;      // --worlds DIR (default: the bundled scenes)
  bool no_worlds = false;  // --no-worlds
};

std::vector<std::string>& ros_args() {
  static std::vector<std::string> tokens;
  return tokens;
}

// --ros-args' parameters (-p, --params-file) applied to the scene and the run's settings before
// step 0: the run starts with them, and a reset returns to them.
Status apply_ros_args(Scene& scene, std::int64_t steps, control::RunSettings& settings,
                      const std::string& ns) {
  Result<std::vector<control::ParameterOverride>> overrides = control::parse_ros_args(ros_args(), "/" + ns);
  if (!overrides) return overrides.error();
  std::vector<std::string> warnings;
  if (Status st = control::apply_overrides(overrides.value(), scene, steps, settings, &warnings); !st)
    return st;
  for (const std::string& w : warnings) std::fprintf(stderr, "%s\n", w.c_str());
  return Ok{};
}

// The DDS sink's options: the run's settings after --ros-args, and the step messages it shares.
node::NodeOptions sink_options(const NodeArgs& a, const control::RunSettings& settings, const Scene& scene) {
  // Each step is encoded once for DDS and the Foxglove server alike.
  node::NodeOptions node_options = a.node;
  node_options.stop = stop_requested;
  node_options.rate = settings.rate;
  node_options.publish_every = settings.publish_every;
  node_options.messages = std::make_shared<msgs::StepMessages>(scene, a.node.ns);
  return node_options;
}

// --foxglove: the server, the sink feeding it and the channel of /<ns>/commands. The sink goes
// before the server (members are destroyed in reverse).
struct NodeFoxglove {
  std::unique_ptr<foxglove::Server> server;
  std::unique_ptr<foxglove::FoxgloveSink> sink;
  foxglove::ChannelId commands_channel = 0;  // /<ns>/commands to viewers, as on DDS
};

// Starts the Foxglove server (which prints its listening line) on the node's topics and
// /<ns>/commands; the exit status when it cannot.
std::optional<int> serve_foxglove(const NodeArgs& a, const control::RunSettings& settings,
                                  const node::NodeOptions& node_options, control::Controller& controller,
                                  const node::NodeName& name, const node::NodeServices& services,
                                  NodeFoxglove& out) {
  foxglove::SinkOptions fo;
  fo.publish_every = settings.publish_every;
  fo.topics = a.node.topics;
  fo.ns = a.node.ns;
  fo.messages = node_options.messages;
  std::vector<foxglove::ChannelId> ids;
  msgs::TopicSet served = fo.topics;
  served.set(static_cast<std::size_t>(msgs::TopicId::Commands));
  auto channels = foxglove::ros2_channels(served, a.node.ns, &ids);
  if (!channels) return fail("node", channels.error().message);
  // simulation_interfaces' services beside the controller's: the handlers the node's DDS services
  // run (one implementation), their commands recorded with source "foxglove".
  std::vector<foxglove::HostedService> hosted;
  for (node::NodeServices::Handled& h : services.simulation_handlers("foxglove")) {
    hosted.push_back(hosted_service(
        name.fully_qualified(), h.name, h.type,
        [handler = std::move(h.handler), type = h.type](std::span<const std::byte> request) -> Result<Bytes> {
          Bytes reply;
          if (!handler(node::RequestHeader{}, request, reply))
            return Error{"a malformed " + type + " request", ErrorCode::InvalidArgument};
          return reply;
        }));
  }
  auto started = start_foxglove("rbsim node", a.foxglove, std::move(channels.value()), &controller,
                                name.fully_qualified(), std::move(hosted));
  if (!started) return fail("node", started.error().message, foxglove_exit_status(started.error()));
  out.server = std::move(started.value());
  out.commands_channel = ids[static_cast<std::size_t>(msgs::TopicId::Commands)];
  out.sink = std::make_unique<foxglove::FoxgloveSink>(*out.server, std::move(ids), fo);
  return std::nullopt;
}

// --wait-for-subscribers: false when a stop came first (nothing published).
bool wait_for_subscribers(const NodeArgs& a, node::DdsSink& sink) {
  if (!a.quiet) RBSIM_LOG(Info, "rbsim node: waiting for %d subscriber(s)...\n", a.wait_for);
  if (!sink.wait_for_subscribers(a.wait_for, stop_requested)) {
    if (!a.quiet) RBSIM_LOG(Info, "rbsim node: stopped while waiting, nothing published\n");
    return false;
  }
  return true;
}

// Rate and publish_every changes reach the pacer and the publishers at a step boundary.
void follow_settings(control::Controller& controller, node::Pacer& pacer, node::DdsSink& sink,
                     foxglove::FoxgloveSink* foxglove_sink) {
  controller.on_settings([&pacer, &sink, foxglove_sink](const control::RunSettings& s) {
    pacer.set_pace(s.rate, s.publish_every);
    sink.set_publish_every(s.publish_every);
    if (foxglove_sink) foxglove_sink->set_publish_every(s.publish_every);
  });
}

// Every applied command goes out on /<ns>/commands over DDS (the node's services) and to viewers;
// a reset's new time goes out on /clock at once. Stamps are the world's (its dt, a loaded world's own).
void publish_commands(control::Controller& controller, node::NodeServices& services, node::DdsSink& sink,
                      const NodeFoxglove& fox) {
  controller.on_command(
      [&controller, &applied = services, &sink, &server = fox.server,
       commands_channel = fox.commands_channel](const control::Command& c, const control::CommandResult& r) {
        applied.command_applied(c, r);
        if (c.kind == control::CommandKind::Reset && r.successful) sink.time_reset();
        if (server && commands_channel != 0) {
          server->publish(commands_channel,
                          msgs::sim_time_ns(r.step >= 0 ? r.step : 0, controller.world_info().dt),
                          applied.last_command());
        }
      });
}

// Every change of a large world re-publishes its scene description and markers (megabytes at
// 10,000 bodies), each a little larger than the last: above glibc's sliding mmap threshold every
// buffer would be mapped afresh, its pages faulted in and unmapped again, twice the cost of the
// change (scripts/bench-node-spawn). The heap keeps them instead, and keeps what it grew to.
void keep_large_buffers() {
  mallopt(M_MMAP_THRESHOLD, 256 << 20);
  mallopt(M_TRIM_THRESHOLD, 512 << 20);
}

// One begin()/run() pass, or one per loop with --loop until a stop; the exit status of a pass
// that failed or diverged.
std::optional<int> run_passes(const NodeArgs& a, Driver& driver, const DriverOptions& options) {
  do {
    if (Status st = driver.begin(); !st) return fail("node", st.error().message);
    const Result<PassEnd> end = driver.run(options);
    if (!end) return fail("node", end.error().message);
    if (end.value() == PassEnd::Diverged) {
      // Subscribers still get every step before it (bounded wait for their acknowledgements).
      const Status flushed = driver.finish();
      return fail("node", describe_divergence(driver.divergence()) + ". Published steps up to " +
                              std::to_string(driver.world().step_index() - 1) +
                              (flushed ? "" : " (" + flushed.error().message + ")") +
                              " (--allow-nonfinite keeps going).");
    }
  } while (a.loop && !stop_requested());
  return std::nullopt;
}

// The end line: steps, speed, messages, service calls, parameter changes, the viewers'.
void print_end_line(const Driver& driver, std::chrono::steady_clock::time_point start,
                    const control::Controller& controller, const node::NodeServices& services,
                    const node::DdsSink& sink, const foxglove::Server* server) {
  const std::int64_t total_steps = driver.steps_done();
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const control::ControlCounters counted = controller.counters();
  const node::NodeServiceCounters served = services.counters();
  const std::string dropped = served.dropped > 0 ? " (" + std::to_string(served.dropped) + " dropped)" : "";
  RBSIM_LOG(
      Info, "rbsim node: %s after %lld steps in %s (%.4g steps/s), %llu messages published, %s%s, %s%s\n",
      stop_requested() ? "stopped" : "done", static_cast<long long>(total_steps),
      format_seconds(wall).c_str(), wall > 0 ? static_cast<double>(total_steps) / wall : 0.0,
      static_cast<unsigned long long>(sink.published()),
      count_of(static_cast<std::int64_t>(served.received), "service call", "service calls").c_str(),
      dropped.c_str(),
      count_of(static_cast<std::int64_t>(counted.parameter_changes), "parameter change", "parameter changes")
          .c_str(),
      server ? ("; " + foxglove_summary(*server)).c_str() : "");
}

int node_command(const NodeArgs& a) {
  // Ctrl-C and SIGTERM only raise a flag from here on, before anything a stop must undo exists
  // (a participant, a listener, an output file): a stop at any stage of start-up ends cleanly.
  install_stop_handlers();
  keep_large_buffers();
  // The node is /<namespace> on the graph: its topics /<namespace>/<name> are its private ones.
  const Result<node::NodeName> name = node::parse_node_name(a.node.ns);
  if (!name) return fail("node", name.error().message, 2);
  auto participant = node::create_dds_participant(a.node.domain, name.value());
  if (!participant) return fail("node", participant.error().message);
  // The node's clock is the simulation's (it publishes /clock): 0 until there is a world.
  const World* clock_world = nullptr;
  auto rosout = node::Rosout::create(participant.value(), [&clock_world] {
    return clock_world != nullptr ? static_cast<std::int64_t>(msgs::sim_time_ns(*clock_world)) : 0;
  });
  if (!rosout) return fail("node", rosout.error().message);
  Result<Scene> loaded = load_scene(a.scene);
  if (!loaded) return fail("node", loaded.error().message);
  Scene& scene = loaded.value();
  for (const std::string& w : scene.warnings) RBSIM_LOG(Warn, "%s", w.c_str());
  const std::int64_t steps = steps_for(a.duration.value_or(scene.duration), scene.world.dt);
  control::RunSettings settings{a.node.rate, a.node.publish_every, false};
  if (Status st = apply_ros_args(scene, steps, settings, a.node.ns); !st) {
    std::fprintf(stderr, "rbsim node: error: %s\nRun 'rbsim node --help' for usage.\n",
                 st.error().message.c_str());
    return 2;
  }
  const node::NodeOptions node_options = sink_options(a, settings, scene);
  auto sink = node::DdsSink::create(participant.value(), node_options);
  if (!sink) return fail("node", sink.error().message);
  // Commands (parameters, pause, step, reset, impulses) apply at step boundaries. The controller
  // outlives every front end that submits to it (the Foxglove server, the node's services).
  control::Controller controller(scene, steps, settings);
  // The node's services (the six parameter services; pause, resume, reset, step, apply_impulse;
  // simulation_interfaces') answer through the controller; every parameter change also goes out on
  // /parameter_events (an observer beside the Foxglove server's parameter updates). They come
  // before the Foxglove server, which offers simulation_interfaces' too by running their handlers,
  // so the server stops (its calls answered or dropped) before the handlers go.
  node::NodeServicesOptions service_options;
  service_options.node = name->fully_qualified();
  // STATE_QUITTING: the node ends as on SIGINT (outputs finished, the end line, exit 0).
  service_options.quit = [quiet = a.quiet] {
    if (!quiet) RBSIM_LOG(Info, "rbsim node: quitting (set_simulation_state STATE_QUITTING)\n");
    request_stop();
  };
  service_options.start_type_description_service = settings.start_type_description_service;
  service_options.introspection = settings.service_introspection;  // -p service_configure_introspection:=...
  if (!a.spawnables.empty()) service_options.spawnables = {a.spawnables};
  if (!a.no_worlds) service_options.worlds = {a.worlds.empty() ? bundled_path("scenes", "scenes") : a.worlds};
  auto services = node::NodeServices::create(participant.value(), controller, service_options);
  if (!services) return fail("node", services.error().message);
  // The Foxglove server serves beside DDS, steered through the controller. The pacer releases
  // each step when it is due; the Foxglove sink's hand-off to the server's thread (a copy and a
  // wake-up) goes first, so viewers do not wait for the DDS writes.
  NodeFoxglove foxglove;
  if (a.foxglove.address) {
    if (std::optional<int> exit =
            serve_foxglove(a, settings, node_options, controller, name.value(), *services.value(), foxglove))
      return *exit;
  }
  if (!a.quiet) {
    RBSIM_LOG(Info, "rbsim node: %s on %s, topics under /%s (and /tf, /clock), rate %s, %lld steps%s\n",
              scene.name.c_str(), participant.value().description().c_str(), a.node.ns.c_str(),
              settings.rate > 0 ? (std::to_string(settings.rate) + "x").c_str() : "as fast as possible",
              static_cast<long long>(steps),
              a.loop            ? ", looping"
              : settings.paused ? ", paused"
                                : "");
  }
  if (a.wait_for > 0 && !wait_for_subscribers(a, *sink.value())) return 0;  // as for a stop while running
  const auto start = std::chrono::steady_clock::now();
  Result<Driver> created = Driver::create(scene);
  if (!created) return fail("node", created.error().message);
  Driver& driver = created.value();
  clock_world = &driver.world();
  struct ForgetWorld {  // the driver goes before the Rosout that reads its clock
    const World*& world;
    ~ForgetWorld() { world = nullptr; }
  } forget_world{clock_world};
  node::Pacer pacer(settings.rate, settings.publish_every);
  driver.add(pacer);
  if (foxglove.sink) driver.add(*foxglove.sink);
  driver.add(*sink.value());
  follow_settings(controller, pacer, *sink.value(), foxglove.sink.get());
  publish_commands(controller, *services.value(), *sink.value(), foxglove);
  DriverOptions options;
  options.steps = steps;
  options.allow_nonfinite = a.allow_nonfinite;
  options.stop = stop_requested;
  options.control = &controller;
  options.pace = [&pacer](const World& world) { pacer.wait(world); };
  if (std::optional<int> exit = run_passes(a, driver, options)) return *exit;
  controller.close("the node stopped");
  if (Status st = driver.finish(); !st) return fail("node", st.error().message);
  if (!a.quiet)
    print_end_line(driver, start, controller, *services.value(), *sink.value(), foxglove.server.get());
  return 0;
}
}  // namespace

void set_ros_args(std::vector<std::string> tokens) {
  ros_args() = std::move(tokens);
}

Subcommand add_node_command(CLI::App& parent) {
  auto a = std::make_shared<NodeArgs>();
  CLI::App* app =
      parent.add_subcommand("node", "Run a scene and publish it live over DDS (ROS 2 conventions)");
  app->add_option("scene", a->scene, "FOSSSim XML scene file")->required();
  app->add_option("--rate", a->node.rate,
                  "Real-time factor (2 = twice as fast as real time; 0 = as fast as possible)")
      ->check(non_negative())
      ->default_str("1");
  app->add_option("--publish-every", a->node.publish_every, "Publish every k-th step")
      ->check(positive())
      ->default_str("1");
  add_domain_option(app, a->node.domain);
  app->add_option("--namespace", a->node.ns, "ROS namespace: topics are /<namespace>/<name>")
      ->check(ros_namespace())
      ->default_str("rbsim");
  app->add_option("--duration", a->duration, "Simulated seconds per run (default: the scene's)")
      ->check(non_negative());
  app->add_flag("--loop", a->loop, "Start the scene again when it ends, until Ctrl-C");
  app->add_flag(
      "--allow-nonfinite", a->allow_nonfinite,
      "Keep going when the simulation diverges (default: stop at the first inf/NaN with an error naming "
      "the step, body and quantity)");
  app->add_option("--wait-for-subscribers", a->wait_for,
                  "Wait until N subscribers match the body states first")
      ->check(non_negative());
  app->add_option("--keep-last", a->node.keep_last,
                  "Per-step writers keep the last N samples instead of all: the node never waits for a slow "
                  "subscriber, which may then lose samples (ROS 2's default profile is keep last 10)")
      ->check(positive());
  add_topics_option(app, a->topics, a->node.ns, a->node.topics, "Topics to publish (DDS and --foxglove)");
  add_foxglove_option(app, a->foxglove);
  app->add_option(
         "--spawnables", a->spawnables,
         "A folder of spawnable fragments (FOSSSim XML of one body each, *.xml): simulation_interfaces' "
         "spawn_entity and spawn_entities take a uri naming a file in it (relative to it, or an "
         "absolute path or file:// URI inside it; no '..', no symbolic links, regular files of at "
         "most 1 MiB), and get_spawnables lists them. Without it the node reads no files")
      ->check(existing_folder());
  app->add_option("--worlds", a->worlds,
                  "A folder of worlds (FOSSSim scenes, *.xml): simulation_interfaces' load_world takes a uri "
                  "naming a file in it (the same rules as --spawnables, files of at most 64 MiB), and "
                  "get_available_worlds lists them (default: the bundled scenes)")
      ->check(existing_folder());
  app->add_flag("--no-worlds", a->no_worlds,
                "No worlds folder: load_world takes a scene's text (resource_string) only")
      ->excludes(app->get_option("--worlds"));
  app->add_flag("-q,--quiet", a->quiet,
                "No start and end lines (--foxglove's listening line is always printed)");
  app->footer(
      "Topics (DDS name rt/<namespace>/<name>, type pkg::msg::dds_::Name_, CDR): scene "
      "(rbsim_msgs/SceneDescription) and markers (visualization_msgs/MarkerArray: body shapes in their "
      "frames), reliable, transient local, keep last 1: late joiners get them; body_states, spring_states, "
      "energy, /tf (tf2_msgs/TFMessage: world -> <namespace>/body_<i>), springs (visualization_msgs/Marker), "
      "/clock (rosgraph_msgs/Clock) and, with --topics, poses (geometry_msgs/PoseArray), all reliable, "
      "volatile, keep all: a slow subscriber slows the node down rather than losing samples (--keep-last N "
      "trades that for a node that never waits).\n"
      "--foxglove serves the same topics (and /<namespace>/commands) to Foxglove beside DDS: encoding cdr, "
      "ros2msg schemas as in MCAP, "
      "log time = simulated time; a client that falls behind loses the oldest per-step messages (never the "
      "latched scene and markers), one that stops reading is disconnected. Its services are the node's: "
      "pause, resume, reset, step, apply_impulse (cdr or json) and simulation_interfaces' (cdr), each "
      "answered as over DDS.\n"
      "Parameters, as a ROS 2 node takes them, after the other options: --ros-args -p NAME:=VALUE "
      "--params-file FILE [--] (rcl's YAML: /NS: or /**: then ros__parameters:). Read-write: rate, "
      "publish_every, paused, forces.<i>.fx|fy (gravity), forces.<i>.beta|fx|fy|pointsperedge (wind), "
      "springs.<j>.k|l0, service_configure_introspection (disabled, metadata or contents: REP 2012 events "
      "of the node's services on <service>/_service_event, off by default, as ROS 2's introspection demos "
      "switch theirs); values typed as YAML types them (2.0 double, 2 integer, true bool). They apply "
      "from step 0, and a reset returns to them. Read-only, given only this way: "
      "start_type_description_service (default true: the node serves <namespace>/get_type_description, "
      "as an rclcpp node does).\n"
      "Exit status: 0 done, or stopped by Ctrl-C/SIGTERM (cleanly); 1 error (bad scene, DDS failure, "
      "divergence, --foxglove port in use); 2 usage error (also a bad --ros-args value or parameters file).");
  return {app, [a] { return node_command(*a); }};
}

}  // namespace rbsim::cli
