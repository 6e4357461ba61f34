// CLI11 validators whose messages read well ("--steps: must be >= 0 (got -1)"); CLI11's own
// NonNegativeNumber prints its range with DBL_MAX written out in full.
#pragma once

#include <CLI/CLI.hpp>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "rbsim/msgs.hpp"
#include "rbsim/ros_env.hpp"

namespace rbsim::cli {

// A number at least `min` (strictly above it when `strict`). A value that is not a number passes
// here and is reported by the option's conversion ("Could not convert").
inline CLI::Validator at_least(double min, bool strict) {
  char bound[32];
  std::snprintf(bound, sizeof bound, "%g", min);
  const std::string rule = std::string(strict ? "must be > " : "must be >= ") + bound;
  return CLI::Validator(
      [min, strict, rule](std::string& value) -> std::string {
        char* end = nullptr;
        const double v = std::strtod(value.c_str(), &end);
        if (end == value.c_str() || *end != '\0') return {};
        if (strict ? v > min : v >= min) return {};
        return rule + " (got " + value + ")";
      },
      std::string(strict ? "> " : ">= ") + bound);
}
inline CLI::Validator ros_namespace() {
  return CLI::Validator(
      [](std::string& value) -> std::string {
        const std::string problem = msgs::ros_namespace_problem(value);
        if (!problem.empty()) return "\"" + value + "\" is not a ROS 2 namespace: it " + problem;
        if (value[0] == '/') value.erase(0, 1);  // topics are /<namespace>/<name> either way
        return {};
      },
      "NAMESPACE");
}

// A folder that exists (a directory, or a link to one).
inline CLI::Validator existing_folder() {
  return CLI::Validator(
      [](std::string& value) -> std::string {
        std::error_code ec;
        if (std::filesystem::is_directory(value, ec)) return {};
        if (std::filesystem::exists(value, ec)) return "\"" + value + "\" is not a folder";
        return "no folder \"" + value + "\"";
      },
      "DIR");
}

// --node-name NAME: the node a DDS command is on the ROS 2 graph ("rbsim_recorder", or with a
// namespace "tools/recorder"); a name that is not a ROS 2 node name is a usage error.
inline CLI::Option* add_node_name_option(CLI::App* app, node::NodeName& out) {
  return app
      ->add_option_function<std::string>(
          "--node-name",
          [&out](const std::string& value) {
            Result<node::NodeName> parsed = node::parse_node_name(value);
            if (!parsed) throw CLI::ValidationError("--node-name", parsed.error().message);
            out = parsed.value();
          },
          "Its ROS 2 node name ([NAMESPACE/]NAME) on the graph (ros_discovery_info, /rosout)")
      ->default_str(out.fully_qualified());
}

// --topics LIST (msgs::parse_topic_set) on `app`, checked once the command line is parsed, so full
// names may use the namespace `ns` holds by then; a bad list is a usage error naming the topic.
// `out` keeps its default (msgs::default_topics()) when the option is not given.
inline CLI::Option* add_topics_option(CLI::App* app, std::string& list, const std::string& ns,
                                      msgs::TopicSet& out, const std::string& what) {
  CLI::Option* opt = app->add_option("--topics", list,
                                     what +
                                         ", comma-separated: scene (always), markers, body_states, "
                                         "spring_states, energy, tf, springs, clock, poses; default all "
                                         "but poses");
  app->parse_complete_callback([opt, &list, &ns, &out] {
    if (opt->count() == 0) return;
    Result<msgs::TopicSet> set = msgs::parse_topic_set(list, ns);
    if (!set) throw CLI::ValidationError("--topics", set.error().message);
    out = set.value();
  });
  return opt;
}

inline CLI::Validator non_negative() {
  return at_least(0, false);
}
inline CLI::Validator positive() {
  return at_least(0, true);
}

}  // namespace rbsim::cli
