#include <vector>

#include "commands.hpp"

int main(int argc, char** argv) {
  CLI::App app{"rbsim: 2D rigid-body simulator for FOSSSim scenes", "rbsim"};
  app.set_version_flag("--version", "rbsim 0.1.0");
  app.require_subcommand(1);
  app.footer("Run 'rbsim <command> --help' for a command's options.");
  const std::vector<rbsim::cli::Subcommand> subcommands = {
      rbsim::cli::add_run_command(app),    rbsim::cli::add_grade_command(app),
      rbsim::cli::add_render_command(app), rbsim::cli::add_plot_command(app),
      rbsim::cli::add_node_command(app),   rbsim::cli::add_record_command(app),
      rbsim::cli::add_replay_command(app), rbsim::cli::add_log_command(app),
      rbsim::cli::add_check_command(app),
  };
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  for (const auto& sub : subcommands) {
    if (sub.app->parsed()) return sub.run();
  }
  return 1;
}
