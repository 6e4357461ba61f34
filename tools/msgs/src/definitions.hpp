#pragma once
#include <string>
#include <string_view>
#include <vector>

#include "rbsim/status.hpp"

namespace rbsim::msgs::detail {
struct Definition {
  std::string_view type;  // "rbsim_msgs/msg/BodyStates", "std_srvs/srv/Trigger"
  std::string_view text;  // the .msg, .srv or .action file
};
const std::vector<Definition>& definitions();  // sorted by type

// Part `part` of a .srv text (request, response: split by exactly one "---" line) or of an .action
// text (goal, result, feedback: exactly two), as rosidl_adapter splits them. The one split, for
// the type hashes (type_hash.cpp) and the schemas of a service's messages (schema.cpp).
Result<std::string> definition_part(std::string_view type, std::string_view text, int part, int parts);
}  // namespace rbsim::msgs::detail
