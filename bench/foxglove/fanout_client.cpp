// A Foxglove WebSocket client that keeps up, for scripts/bench-foxglove (b): it subscribes to every
// advertised channel, reads every frame, counts messages and bytes, and checks that each channel
// that repeats advances its log time by exactly --dt-ns (a drop shows as a gap). It decodes no
// payload: it measures what the server delivers, not what a client spends decoding (the Node
// clients of test/foxglove_client do that). One JSON line when the server closes:
//   {"messages": N, "bytes": B, "gaps": G, "statuses": ["...", ...]}
// Usage: rbsim_bench_fox_client ws://127.0.0.1:PORT [--dt-ns N] [--timeout S]
#include <bit>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "ws_client.hpp"  // test/foxglove: the server tests' client

static_assert(std::endian::native == std::endian::little, "messageData fields are read as they lie");

int main(int argc, char** argv) {
  constexpr const char* kPrefix = "ws://127.0.0.1:";  // loopback only, as the client connects
  if (argc < 2 || std::strncmp(argv[1], kPrefix, std::strlen(kPrefix)) != 0) {
    std::fprintf(stderr, "usage: rbsim_bench_fox_client ws://127.0.0.1:PORT [--dt-ns N] [--timeout S]\n");
    return 2;
  }
  std::uint64_t dt_ns = 1'000'000;
  int timeout_s = 120;
  for (int i = 2; i + 1 < argc; i += 2) {
    if (std::strcmp(argv[i], "--dt-ns") == 0) dt_ns = std::stoull(argv[i + 1]);
    if (std::strcmp(argv[i], "--timeout") == 0) timeout_s = std::stoi(argv[i + 1]);
  }
  const int port = std::stoi(argv[1] + std::strlen(kPrefix));

  rbsim::foxglove::test::WsClient c;
  if (c.connect(static_cast<std::uint16_t>(port), {"foxglove.websocket.v1"}) != 101) {
    std::fprintf(stderr, "cannot connect to %s: %s\n", argv[1], c.response().c_str());
    return 1;
  }
  c.set_timeout(std::chrono::seconds(timeout_s));

  std::uint64_t messages = 0, bytes = 0, gaps = 0;
  std::map<std::uint32_t, std::uint64_t> last;  // subscription -> last log time
  std::vector<std::string> statuses;
  std::uint32_t next_sub = 1;
  rbsim::foxglove::test::WsClient::Frame f;  // one buffer for every frame
  while (c.read(f)) {
    const std::string& payload = f.data;
    if (f.opcode == 8) {  // close: answer it and end
      (void)c.send_close(payload.substr(0, 2));
      break;
    }
    if (f.opcode == 1) {
      const auto j = nlohmann::json::parse(payload, nullptr, false);
      if (j.is_discarded()) continue;
      const std::string op = j.value("op", "");
      if (op == "advertise") {
        nlohmann::json subs = nlohmann::json::array();
        for (const auto& ch : j["channels"]) subs.push_back({{"id", next_sub++}, {"channelId", ch["id"]}});
        (void)c.send_text(nlohmann::json{{"op", "subscribe"}, {"subscriptions", subs}}.dump());
      } else if (op == "status") {
        statuses.push_back(j.value("message", ""));
      }
      continue;
    }
    if (f.opcode == 2 && payload.size() >= 13 && payload[0] == 1) {
      std::uint32_t sub = 0;
      std::uint64_t t = 0;
      std::memcpy(&sub, payload.data() + 1, 4);  // little-endian, as this host
      std::memcpy(&t, payload.data() + 5, 8);
      ++messages;
      bytes += payload.size() - 13;
      const auto it = last.find(sub);
      if (it != last.end() && t != it->second + dt_ns) ++gaps;
      last[sub] = t;
    }
  }
  nlohmann::json out{{"messages", messages}, {"bytes", bytes}, {"gaps", gaps}, {"statuses", statuses}};
  std::printf("%s\n", out.dump().c_str());
  return 0;
}
