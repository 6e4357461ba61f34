// A Foxglove WebSocket client that keeps up, for scripts/bench-foxglove (b): it subscribes to every
// advertised channel, reads every frame, counts messages and bytes, and checks that each channel
// that repeats advances its log time by exactly --dt-ns (a drop shows as a gap). It decodes no
// payload: it measures what the server delivers, not what a client spends decoding (the Node
// clients of test/foxglove_client do that). One JSON line when the server closes:
//   {"messages": N, "bytes": B, "gaps": G, "statuses": ["...", ...]}
// Usage: rbsim_bench_fox_client ws://127.0.0.1:PORT [--dt-ns N] [--timeout S]
#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <bit>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

static_assert(std::endian::native == std::endian::little, "messageData fields are read as they lie");

namespace {

class Conn {
 public:
  explicit Conn(int fd, int timeout_ms) : fd_(fd), timeout_ms_(timeout_ms) {}
  // Exactly n bytes into out (false: closed, error or timeout).
  bool read(char* out, std::size_t n) {
    while (n > 0) {
      if (at_ == end_) {
        pollfd p{fd_, POLLIN, 0};
        if (::poll(&p, 1, timeout_ms_) <= 0) return false;
        const ssize_t got = ::recv(fd_, buf_.data(), buf_.size(), 0);
        if (got <= 0) return false;
        at_ = 0;
        end_ = static_cast<std::size_t>(got);
      }
      const std::size_t k = std::min(n, end_ - at_);
      std::memcpy(out, buf_.data() + at_, k);
      at_ += k;
      out += k;
      n -= k;
    }
    return true;
  }
  bool write(const std::string& s) {
    return ::send(fd_, s.data(), s.size(), MSG_NOSIGNAL) == static_cast<ssize_t>(s.size());
  }
  // A masked client frame (RFC 6455 5.3; the mask may be any value, zero included).
  bool send_frame(std::uint8_t opcode, const std::string& payload) {
    std::string f;
    f.push_back(static_cast<char>(0x80 | opcode));
    const std::size_t n = payload.size();
    if (n < 126) {
      f.push_back(static_cast<char>(0x80 | n));
    } else {
      f.push_back(static_cast<char>(0x80 | 126));
      f.push_back(static_cast<char>((n >> 8) & 0xFF));
      f.push_back(static_cast<char>(n & 0xFF));
    }
    f.append(4, '\0');
    f += payload;
    return write(f);
  }

 private:
  int fd_;
  int timeout_ms_;
  std::vector<char> buf_ = std::vector<char>(1 << 20);
  std::size_t at_ = 0, end_ = 0;
};

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || std::strncmp(argv[1], "ws://", 5) != 0) {
    std::fprintf(stderr, "usage: rbsim_bench_fox_client ws://HOST:PORT [--dt-ns N] [--timeout S]\n");
    return 2;
  }
  std::uint64_t dt_ns = 1'000'000;
  int timeout_s = 120;
  for (int i = 2; i + 1 < argc; i += 2) {
    if (std::strcmp(argv[i], "--dt-ns") == 0) dt_ns = std::stoull(argv[i + 1]);
    if (std::strcmp(argv[i], "--timeout") == 0) timeout_s = std::stoi(argv[i + 1]);
  }
  const std::string hostport = argv[1] + 5;
  const auto colon = hostport.rfind(':');
  const std::string host = hostport.substr(0, colon);
  const int port = std::stoi(hostport.substr(colon + 1));

  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<std::uint16_t>(port));
  if (fd < 0 || ::inet_pton(AF_INET, host.c_str(), &addr.sin_addr) != 1 ||
      ::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
    std::fprintf(stderr, "cannot connect to %s\n", argv[1]);
    return 1;
  }
  const int one = 1;
  ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
  Conn c(fd, timeout_s * 1000);
  if (!c.write("GET / HTTP/1.1\r\nHost: " + hostport +
               "\r\nUpgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Key: "
               "cmJzaW0tYmVuY2gtY2xpZW50\r\nSec-WebSocket-Version: 13\r\nSec-WebSocket-Protocol: "
               "foxglove.websocket.v1\r\n\r\n")) {
    return 1;
  }
  std::string head;
  for (char ch = 0; head.size() < 8192 && head.find("\r\n\r\n") == std::string::npos;) {
    if (!c.read(&ch, 1)) return std::fprintf(stderr, "no handshake answer\n"), 1;
    head.push_back(ch);
  }
  if (head.find(" 101 ") == std::string::npos) return std::fprintf(stderr, "refused: %s\n", head.c_str()), 1;

  std::uint64_t messages = 0, bytes = 0, gaps = 0;
  std::map<std::uint32_t, std::uint64_t> last;  // subscription -> last log time
  std::vector<std::string> statuses;
  std::uint32_t next_sub = 1;
  std::vector<char> payload;
  while (true) {
    char h[2];
    if (!c.read(h, 2)) break;
    const auto opcode = static_cast<std::uint8_t>(h[0] & 0x0F);
    std::uint64_t n = static_cast<std::uint8_t>(h[1]) & 0x7F;
    if (n >= 126) {
      unsigned char ext[8];
      const std::size_t k = n == 126 ? 2 : 8;
      if (!c.read(reinterpret_cast<char*>(ext), k)) break;
      n = 0;
      for (std::size_t i = 0; i < k; ++i) n = (n << 8) | ext[i];
    }
    if (n > (std::uint64_t{1} << 30)) break;
    payload.resize(n);
    if (!c.read(payload.data(), n)) break;
    if (opcode == 8) {  // close: answer it and end
      (void)c.send_frame(8, std::string(payload.begin(), payload.begin() + std::min<std::size_t>(n, 2)));
      break;
    }
    if (opcode == 9) {
      (void)c.send_frame(10, std::string(payload.begin(), payload.end()));
      continue;
    }
    if (opcode == 1) {
      const auto j = nlohmann::json::parse(payload.begin(), payload.end(), nullptr, false);
      if (j.is_discarded()) continue;
      const std::string op = j.value("op", "");
      if (op == "advertise") {
        nlohmann::json subs = nlohmann::json::array();
        for (const auto& ch : j["channels"]) subs.push_back({{"id", next_sub++}, {"channelId", ch["id"]}});
        (void)c.send_frame(1, nlohmann::json{{"op", "subscribe"}, {"subscriptions", subs}}.dump());
      } else if (op == "status") {
        statuses.push_back(j.value("message", ""));
      }
      continue;
    }
    if (opcode == 2 && n >= 13 && payload[0] == 1) {
      std::uint32_t sub = 0;
      std::uint64_t t = 0;
      std::memcpy(&sub, payload.data() + 1, 4);  // little-endian, as this host
      std::memcpy(&t, payload.data() + 5, 8);
      ++messages;
      bytes += n - 13;
      const auto it = last.find(sub);
      if (it != last.end() && t != it->second + dt_ns) ++gaps;
      last[sub] = t;
    }
  }
  ::close(fd);
  nlohmann::json out{{"messages", messages}, {"bytes", bytes}, {"gaps", gaps}, {"statuses", statuses}};
  std::printf("%s\n", out.dump().c_str());
  return 0;
}
