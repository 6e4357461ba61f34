#include <algorithm>
#include <csignal>
#include <cstdio>
#include <string>
#include <vector>

#include "commands.hpp"
#include "rbsim/core.hpp"
#include "rbsim/ros_args.hpp"

namespace {

// The deepest subcommand CLI11 had reached when parsing stopped: "rbsim check", "rbsim log recover".
CLI::App* reached(CLI::App* app) {
  for (CLI::App* sub : app->get_subcommands([](CLI::App* s) { return s->parsed() > 0; })) return reached(sub);
  return app;
}

std::string command_path(const CLI::App* app) {
  std::string path = app->get_name();
  for (const CLI::App* p = app->get_parent(); p != nullptr; p = p->get_parent())
    path = p->get_name() + " " + path;
  return path;
}

std::string command_names(CLI::App& app) {
  std::string names;
  for (const CLI::App* sub : app.get_subcommands({})) names += (names.empty() ? "" : ", ") + sub->get_name();
  return names;
}

// Usage errors: one line naming the command and what is wrong, a pointer to its help, exit 2
// (CLI11's own codes, 100 and up, are not what a shell user expects).
int usage_error(CLI::App* command, const std::string& what) {
  const std::string path = command_path(command);
  std::fprintf(stderr, "%s: error: %s\nRun '%s --help' for usage.\n", path.c_str(), what.c_str(),
               path.c_str());
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  // Past a file-size limit (ulimit -f) a write fails with EFBIG and the command stops with an error
  // naming the file and the bytes written, instead of SIGXFSZ killing it mid-write.
  std::signal(SIGXFSZ, SIG_IGN);
  CLI::App app{"rbsim: 2D rigid-body simulator for FOSSSim scenes", "rbsim"};
  app.set_version_flag("--version", std::string("rbsim ") + rbsim::version());
  app.require_subcommand(1);
  app.footer(
      "Run 'rbsim <command> --help' (or 'rbsim help <command>') for a command's options.\n"
      "Exit status: 0 success, 1 failure (the command's help says which), 2 usage error.");
  const std::vector<rbsim::cli::Subcommand> subcommands = {
      rbsim::cli::add_run_command(app),      rbsim::cli::add_grade_command(app),
      rbsim::cli::add_render_command(app),   rbsim::cli::add_plot_command(app),
      rbsim::cli::add_node_command(app),     rbsim::cli::add_record_command(app),
      rbsim::cli::add_replay_command(app),   rbsim::cli::add_log_command(app),
      rbsim::cli::add_check_command(app),    rbsim::cli::add_bridge_command(app),
      rbsim::cli::add_security_command(app),
  };
  if (argc == 1) return usage_error(&app, "no command given (commands: " + command_names(app) + ")");
  // `rbsim help [command [subcommand]]`, as git has it: the same as `rbsim command --help`.
  std::vector<std::string> args(argv, argv + argc);
  if (args[1] == "help") {
    args.erase(args.begin() + 1);
    args.push_back("--help");
  }
  // Name an unknown command (CLI11 would only say that a subcommand is required).
  CLI::App* level = &app;
  for (std::size_t i = 1; i < args.size() && !args[i].empty() && args[i][0] != '-'; ++i) {
    if (level->get_subcommands({}).empty()) break;
    CLI::App* sub = nullptr;
    try {
      sub = level->get_subcommand(args[i]);
    } catch (const CLI::OptionNotFound&) {
      return usage_error(level,
                         "unknown command '" + args[i] + "' (commands: " + command_names(*level) + ")");
    }
    level = sub;
  }
  // ROS 2's arguments (--ros-args ... [--]) are rbsim node's: cut out before CLI11 sees them. For
  // any other command they stay, and CLI11 calls them unexpected.
  if (level->get_name() == "node") rbsim::cli::set_ros_args(rbsim::control::take_ros_args(args));
  std::reverse(args.begin(), args.end());  // CLI11 takes the arguments last first
  args.pop_back();                         // without the program name
  try {
    app.parse(args);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    return usage_error(reached(&app), e.what());
  }
  for (const auto& sub : subcommands) {
    if (sub.app->parsed()) return sub.run();
  }
  return 1;
}
