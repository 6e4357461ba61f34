// The rbsim subcommands: each adds itself to the CLI11 app and returns how to run it.
#pragma once

#include <CLI/CLI.hpp>

#include <cstdint>
#include <functional>

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
Subcommand add_record_command(CLI::App& parent);  // record.cpp
Subcommand add_replay_command(CLI::App& parent);  // replay.cpp
Subcommand add_log_command(CLI::App& parent);     // log.cpp: info, doctor, recover, export
Subcommand add_check_command(CLI::App& parent);   // check.cpp: golden-log comparison

// The DDS commands' --domain (record.cpp): bound to `domain`, which starts as ROS_DOMAIN_ID (or 0),
// so the command line wins; an invalid ROS_DOMAIN_ID leaves node::kDomainFromEnvironment for
// Participant::create to report. Also puts the help on ROS 2's DDS environment variables before
// the command's own footer.
CLI::Option* add_domain_option(CLI::App* app, std::uint32_t& domain);

}  // namespace rbsim::cli
