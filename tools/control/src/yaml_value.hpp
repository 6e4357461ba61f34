// YAML scalars typed as ROS 2 types parameters (rcl_yaml_param_parser), shared by --ros-args,
// parameters files and command scripts. Internal to control: yaml-cpp stays out of its headers.
#pragma once

#include <yaml-cpp/yaml.h>

#include <string>

#include "rbsim/parameters.hpp"
#include "rbsim/status.hpp"

namespace rbsim::control {

// One scalar as rcl types it: a string tag or quotes make a string; then bool words
// (Y/y/yes/true/on/... and their negatives), a whole strtoll (base 0), a whole strtod (with YAML's
// .nan and .inf), else a string.
ParameterValue yaml_scalar(const YAML::Node& node);
// A parameter's value: a scalar, or a sequence of scalars of one type (an array parameter).
Result<ParameterValue> yaml_value(const YAML::Node& node);
// "path:LINE" of a node, for messages.
std::string yaml_line(const std::string& path, const YAML::Node& node);

}  // namespace rbsim::control
