#pragma once
#include <string_view>
#include <vector>

namespace rbsim::msgs::detail {
struct Definition {
  std::string_view type;  // "rbsim_msgs/msg/BodyStates", "std_srvs/srv/Trigger"
  std::string_view text;  // the .msg, .srv or .action file
};
const std::vector<Definition>& definitions();  // sorted by type
}  // namespace rbsim::msgs::detail
