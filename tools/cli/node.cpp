// rbsim node: run a scene and stream it over DDS with ROS 2 conventions.
#include <chrono>
#include <cstdio>
#include <memory>

#include "cli_util.hpp"
#include "commands.hpp"
#include "rbsim/dds_sink.hpp"
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
  std::optional<std::string> foxglove;  // [ADDR:]PORT
};

int node_command(const NodeArgs& a) {
  // The node is /<namespace> on the graph: its topics /<namespace>/<name> are its private ones.
  const Result<node::NodeName> name = node::parse_node_name(a.node.ns);
  if (!name) return fail("node", name.error().message, 2);
  auto participant = node::Participant::create(a.node.domain, name.value());
  if (!participant) return fail("node", participant.error().message);
  // The node's clock is the simulation's (it publishes /clock): 0 until there is a world.
  const World* clock_world = nullptr;
  auto rosout = node::Rosout::create(participant.value(), [&clock_world] {
    return clock_world != nullptr ? static_cast<std::int64_t>(msgs::sim_time_ns(*clock_world)) : 0;
  });
  if (!rosout) return fail("node", rosout.error().message);
  Result<Scene> loaded = load_scene(a.scene);
  if (!loaded) return fail("node", loaded.error().message);
  const Scene& scene = loaded.value();
  for (const std::string& w : scene.warnings) RBSIM_LOG(Warn, "%s", w.c_str());
  const std::int64_t steps = steps_for(a.duration.value_or(scene.duration), scene.world.dt);
  // Each step is encoded once for DDS and the Foxglove server alike.
  node::NodeOptions node_options = a.node;
  node_options.messages = std::make_shared<msgs::StepMessages>(scene, a.node.ns);
  auto sink = node::DdsSink::create(participant.value(), node_options);
  if (!sink) return fail("node", sink.error().message);
  // The Foxglove server serves beside DDS. The pacer releases each step when it is due; the
  // Foxglove sink's hand-off to the server's thread (a copy and a wake-up) goes first, so
  // viewers do not wait for the DDS writes.
  std::unique_ptr<foxglove::Server> server;
  std::unique_ptr<foxglove::FoxgloveSink> foxglove_sink;
  if (a.foxglove) {
    foxglove::SinkOptions fo;
    fo.publish_every = a.node.publish_every;
    fo.topics = a.node.topics;
    fo.ns = a.node.ns;
    fo.messages = node_options.messages;
    std::vector<foxglove::ChannelId> ids;
    auto channels = foxglove::ros2_channels(fo.topics, a.node.ns, &ids);
    if (!channels) return fail("node", channels.error().message);
    auto started = start_foxglove("rbsim node", *a.foxglove, std::move(channels.value()));
    if (!started) return fail("node", started.error().message);
    server = std::move(started.value());
    foxglove_sink = std::make_unique<foxglove::FoxgloveSink>(*server, std::move(ids), fo);
  }
  install_stop_handlers();
  if (!a.quiet) {
    RBSIM_LOG(Info,
              "rbsim node: %s on domain %u, topics under /%s (and /tf, /clock), rate %s, %lld steps%s\n",
              scene.name.c_str(), a.node.domain, a.node.ns.c_str(),
              a.node.rate > 0 ? (std::to_string(a.node.rate) + "x").c_str() : "as fast as possible",
              static_cast<long long>(steps), a.loop ? ", looping" : "");
  }
  if (a.wait_for > 0) {
    if (!a.quiet) RBSIM_LOG(Info, "rbsim node: waiting for %d subscriber(s)...\n", a.wait_for);
    if (!sink.value()->wait_for_subscribers(a.wait_for, stop_requested)) return 128 + stop_signal();
  }
  const auto start = std::chrono::steady_clock::now();
  Result<Driver> created = Driver::create(scene);
  if (!created) return fail("node", created.error().message);
  Driver& driver = created.value();
  clock_world = &driver.world();
  struct ForgetWorld {  // the driver goes before the Rosout that reads its clock
    const World*& world;
    ~ForgetWorld() { world = nullptr; }
  } forget_world{clock_world};
  node::Pacer pacer(a.node.rate, a.node.publish_every);
  driver.add(pacer);
  if (foxglove_sink) driver.add(*foxglove_sink);
  driver.add(*sink.value());
  DriverOptions options;
  options.steps = steps;
  options.allow_nonfinite = a.allow_nonfinite;
  options.stop = stop_requested;
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
  if (Status st = driver.finish(); !st) return fail("node", st.error().message);
  if (!a.quiet) {
    const std::int64_t total_steps = driver.steps_done();
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    RBSIM_LOG(Info, "rbsim node: %s after %lld steps in %s (%.4g steps/s), %llu messages published%s\n",
              stop_requested() ? "stopped" : "done", static_cast<long long>(total_steps),
              format_seconds(wall).c_str(), wall > 0 ? static_cast<double>(total_steps) / wall : 0.0,
              static_cast<unsigned long long>(sink.value()->published()),
              server ? ("; " + foxglove_summary(*server)).c_str() : "");
  }
  return 0;
}
}  // namespace

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
      "--foxglove serves the same topics to Foxglove beside DDS: encoding cdr, ros2msg schemas as in MCAP, "
      "log time = simulated time; a client that falls behind loses the oldest per-step messages (never the "
      "latched scene and markers), one that stops reading is disconnected.\n"
      "Exit status: 0 done, or stopped by Ctrl-C/SIGTERM (cleanly); 1 error (bad scene, DDS failure, "
      "divergence, --foxglove port in use); 2 usage error.");
  return {app, [a] { return node_command(*a); }};
}

}  // namespace rbsim::cli
