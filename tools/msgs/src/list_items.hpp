// The one splitter of msgs' comma-separated lists: a --topics list (parse_topic_set) and an array's
// default value in a .msg ("[0, 1.5]", type_hash.cpp).
#pragma once

#include <string_view>
#include <vector>

namespace rbsim::msgs::detail {

// The items of `list` split at each ',', spaces around each trimmed; a trailing ',' adds no item
// ("a, b," is a and b), an empty one between two commas stays (the caller decides what it means).
inline std::vector<std::string_view> list_items(std::string_view list) {
  std::vector<std::string_view> items;
  while (!list.empty()) {
    const auto comma = list.find(',');
    std::string_view item = list.substr(0, comma);
    list = comma == std::string_view::npos ? std::string_view() : list.substr(comma + 1);
    while (!item.empty() && item.front() == ' ') item.remove_prefix(1);
    while (!item.empty() && item.back() == ' ') item.remove_suffix(1);
    items.push_back(item);
  }
  return items;
}

}  // namespace rbsim::msgs::detail
