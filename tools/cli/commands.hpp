// The rbsim subcommands: each adds itself to the CLI11 app and returns how to run it.
#pragma once

#include <CLI/CLI.hpp>

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "rbsim/foxglove.hpp"

namespace rbsim::cli {

struct Subcommand {
  CLI::App* app = nullptr;
  std::function<int()> run;  // returns the process exit code
};

Subcommand add_run_command(CLI::App& parent);
Subcommand add_grade_command(CLI::App& parent);
Subcommand add_render_command(CLI::App& parent);  // render.cpp
Subcommand add_plot_command(CLI::App& parent);    // render.cpp
Subcommand add_node_command(CLI::App& parent);    // node.cpp
// The tokens of rbsim node's --ros-args sections, cut from the command line before parsing (main.cpp).
void set_ros_args(std::vector<std::string> tokens);  // node.cpp
Subcommand add_record_command(CLI::App& parent);     // record.cpp
Subcommand add_replay_command(CLI::App& parent);     // replay.cpp
Subcommand add_log_command(CLI::App& parent);        // log.cpp: info, doctor, recover, export
Subcommand add_check_command(CLI::App& parent);      // check.cpp: golden-log comparison
Subcommand add_bridge_command(CLI::App& parent);     // bridge.cpp: DDS -> Foxglove relay
Subcommand add_security_command(CLI::App& parent);   // security.cpp: SROS2 keystore and enclaves

// The DDS commands' --domain (record.cpp): bound to `domain`, which starts as ROS_DOMAIN_ID (or 0),
// so the command line wins; an invalid ROS_DOMAIN_ID leaves node::kDomainFromEnvironment for
// node::create_dds_participant to report. Also puts the help on ROS 2's DDS environment variables before
// the command's own footer.
CLI::Option* add_domain_option(CLI::App* app, std::uint32_t& domain);

// --foxglove [ADDR:]PORT and its access options, shared by rbsim node, replay and bridge.
struct FoxgloveArgs {
  std::optional<std::string> address;  // [ADDR:]PORT; unset: no server
  std::string token_file;              // --foxglove-token-file (else RBSIM_FOXGLOVE_TOKEN)
  bool insecure = false;               // --foxglove-insecure: no token beyond loopback
  bool print_token = false;            // --print-token: the printed links carry the token
  std::uint32_t max_clients = 16;      // --foxglove-max-clients
  std::vector<std::string> tls;        // --foxglove-tls CERT KEY: wss://
};
// --foxglove and the options above (foxglove.cpp): a bad value is a usage error naming the option.
CLI::Option* add_foxglove_option(CLI::App* app, FoxgloveArgs& args, bool required = false);
// Starts the Foxglove server on `args.address` and prints, prefixed with `command`, the line
// "foxglove: listening on ws://ADDR:PORT" (the actual port), the app.foxglove.dev link and where the
// layout file is. Errors: a port in use, an address not on this host; with ErrorCode::InvalidArgument
// (a usage error, exit 2) a token file or RBSIM_FOXGLOVE_TOKEN refused, a non-loopback address
// without a token or --foxglove-insecure.
// With a steering (rbsim node's controller, rbsim bridge's relay; `node`, the steered node's fully
// qualified name, prefixes the services) the server offers parameters and services; `hosted`
// services are offered too (rbsim replay's player, with no steering).
Result<std::unique_ptr<foxglove::Server>> start_foxglove(const char* command, const FoxgloveArgs& args,
                                                         std::vector<foxglove::ChannelSpec> channels,
                                                         control::Steering* steering = nullptr,
                                                         const std::string& node = "/rbsim",
                                                         std::vector<foxglove::HostedService> hosted = {});
// A service the Foxglove server hosts (cdr calls, on its service thread): spec <node>/<name> of ROS 2
// type `type`, each call's request CDR handed to `call`, whose reply CDR answers it and whose error
// fails it with its message. rbsim node's simulation_interfaces handlers, rbsim bridge's forwards
// of them to the node, rbsim replay's player services.
foxglove::HostedService hosted_service(const std::string& node, const std::string& name,
                                       const std::string& type,
                                       std::function<Result<Bytes>(std::span<const std::byte>)> call);
// The exit status for start_foxglove's error: 2 for a usage error, else 1.
int foxglove_exit_status(const Error& error);
// "foxglove: 2 clients, 1200 messages queued, 0 dropped for slow clients" for a command's end line.
std::string foxglove_summary(const foxglove::Server& server);

}  // namespace rbsim::cli
