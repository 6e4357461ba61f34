// Helpers the protocol's sources share (src/protocol.cpp: the frames and the queue;
// src/parameters.cpp: the parameter ops and values).
#pragma once

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

#include "rbsim/foxglove.hpp"

namespace rbsim::foxglove::detail {

// A client's value quoted in an error: compact JSON, at most 40 characters.
inline std::string shown(const nlohmann::json& j) {
  std::string s = j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  if (s.size() > 40) s = s.substr(0, 37) + "...";
  return s;
}

// nlohmann's parser keeps its own stack, but a deeply nested value is still walked recursively
// elsewhere (dump, compare): no client message of this protocol nests deeper than 3.
inline constexpr int kMaxDepth = 16;
inline bool too_deep(std::string_view text) {
  int depth = 0;
  bool in_string = false, escaped = false;
  for (char c : text) {
    if (in_string) {
      if (escaped) {
        escaped = false;
      } else if (c == '\\') {
        escaped = true;
      } else if (c == '"') {
        in_string = false;
      }
      continue;
    }
    if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (++depth > kMaxDepth) return true;
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
  return false;
}

// Collects the problems of one frame into one status error, naming the first few.
struct Problems {
  std::vector<std::string> list;
  std::size_t count = 0;
  void add(std::string p) {
    if (list.size() < 5) list.push_back(std::move(p));
    ++count;
  }
  void flush(std::vector<std::string>& replies) const {
    if (count == 0) return;
    std::string m;
    for (const std::string& p : list) m += (m.empty() ? "" : "; ") + p;
    if (count > list.size()) m += "; and " + std::to_string(count - list.size()) + " more";
    replies.push_back(status_json(StatusLevel::Error, m));
  }
};

// getParameters, setParameters, subscribeParameterUpdates or unsubscribeParameterUpdates (`op`)
// into `out.parameters`; problems are added to `problems` (one status error for the frame).
void parameter_op(const std::string& op, const nlohmann::json& j, ClientProtocol::Outcome& out,
                  Problems& problems);

// clientPublish's ops (src/client_publish.cpp): advertise and unadvertise of client channels, and
// a client's binary messageData (opcode 0x01) into `out.published`.
struct PublishOps {
  static void advertise(ClientProtocol& p, const nlohmann::json& j, Problems& problems);
  static void unadvertise(ClientProtocol& p, const nlohmann::json& j, Problems& problems);
  static void message(ClientProtocol& p, std::string_view frame, ClientProtocol::Outcome& out);
};

}  // namespace rbsim::foxglove::detail
