// ROS 2's command-line arguments for parameters, as rcl reads them:
//   rbsim node SCENE --ros-args -p rate:=2.0 -p forces.0.fy:=-3.7 --params-file params.yaml
// Supported inside --ros-args (up to a lone `--` or the end; several sections may appear):
// `-p NAME:=VALUE` / `--param NAME:=VALUE` and `--params-file FILE`, applied in the order given
// (the last value of a name wins, as rcl collects them). Other ROS arguments (-r remapping,
// --log-level, -e enclave, ...) are usage errors naming them.
//
// Values are typed by YAML exactly as rcl types them (rcl_yaml_param_parser's get_value): a
// quoted or !!str scalar is a string; Y/y/yes/Yes/YES/true/True/TRUE/on/On/ON and their negatives
// (N, no, false, off, ...) are bools; what strtoll reads whole (base 0: 10, 0x1f, 017) is an
// integer; what strtod reads whole (and .nan, .inf, -.inf in YAML's spellings) is a double; the
// rest are strings. A sequence is an array of its elements' one type (mixing types is an error).
//
// A parameters file is rcl's YAML: node keys, then `ros__parameters:`, then the parameters, nested
// maps joined with '.' (`forces: {0: {fy: -3.7}}` is forces.0.fy). A node key is a fully
// qualified node name, possibly split over nested keys (`/ns:` then `node:`), with rcl's wildcards
// as whole segments (`/**` any number of segments, `*` one): the keys that match this node's name
// (`/NS` for rbsim node --namespace NS) apply, in file order; others are ignored.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "rbsim/parameters.hpp"
#include "rbsim/status.hpp"

namespace rbsim::control {

// Removes every `--ros-args ... [--]` section from `args` (program arguments, any position) and
// returns the tokens inside them, in order.
std::vector<std::string> take_ros_args(std::vector<std::string>& args);

// The overrides of ROS arguments for the node `node_name` (fully qualified, e.g. "/rbsim"). Errors
// are one line naming where: "-p rate:=x: ...", "params.yaml:4: parameter 'rate': ...",
// "params.yaml:3: not valid YAML: ...".
Result<std::vector<ParameterOverride>> parse_ros_args(const std::vector<std::string>& tokens,
                                                      const std::string& node_name);
// The overrides a parameters file gives `node_name`; `path` names it in messages.
Result<std::vector<ParameterOverride>> parse_params_file(const std::string& path,
                                                         const std::string& node_name);
Result<std::vector<ParameterOverride>> parse_params_yaml(std::string_view text, const std::string& path,
                                                         const std::string& node_name);
// One value as `-p NAME:=VALUE` types it (VALUE parsed as a YAML document).
Result<ParameterValue> parse_parameter_value(std::string_view text);
// Whether a node key (rcl's wildcards allowed) matches a fully qualified node name.
bool node_name_matches(std::string_view pattern, std::string_view node_name);

}  // namespace rbsim::control
