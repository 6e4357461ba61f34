// A minimal WebSocket client over a blocking POSIX socket, for the server tests and the fan-out
// benchmark's client (bench/foxglove/fanout_client.cpp): the opening handshake with chosen
// subprotocols, masked client frames, unmasked server frames. Every read has a timeout, so a test
// never hangs on a server that does not answer. 127.0.0.1 only.
#pragma once

#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

namespace rbsim::foxglove::test {

class WsClient {
 public:
  WsClient() = default;
  WsClient(const WsClient&) = delete;
  WsClient& operator=(const WsClient&) = delete;
  ~WsClient() { close(); }

  // Connects and performs the handshake; returns the HTTP status line's code (101 on success) or
  // -1 on a socket error. `rcvbuf` > 0 shrinks the receive buffer (a slow client's window).
  // `target` is the request target ("/?token=..."), `headers` more header lines ("Name: value\r\n").
  int connect(std::uint16_t port, const std::vector<std::string>& subprotocols, int rcvbuf = 0,
              const std::string& target = "/", const std::string& headers = "") {
    fd_ = ::socket(AF_INET, SOCK_STREAM, 0);
    if (fd_ < 0) return -1;
    if (rcvbuf > 0) ::setsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &rcvbuf, sizeof rcvbuf);
    set_timeout(std::chrono::milliseconds(5000));
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_port = htons(port);
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (::connect(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) return -1;
    std::string req = "GET " + target +
                      " HTTP/1.1\r\nHost: 127.0.0.1\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
                      "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n" +
                      headers;
    if (!subprotocols.empty()) {
      req += "Sec-WebSocket-Protocol: ";
      for (std::size_t i = 0; i < subprotocols.size(); ++i) req += (i ? ", " : "") + subprotocols[i];
      req += "\r\n";
    }
    req += "\r\n";
    if (!write_all(req.data(), req.size())) return -1;
    // The response header, byte by byte up to the blank line (frames may follow at once).
    std::string head;
    char c;
    while (head.size() < 16384 && head.find("\r\n\r\n") == std::string::npos) {
      if (::recv(fd_, &c, 1, 0) != 1) return -1;
      head.push_back(c);
    }
    response_ = head;
    if (head.size() < 12) return -1;
    return std::atoi(head.substr(9, 3).c_str());
  }

  // Only the TCP connection (no handshake): a socket that never speaks.
  bool open_only(std::uint16_t port) {
    fd_ = ::socket(AF_INET, SOCK_STREAM, 0);
    if (fd_ < 0) return false;
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_port = htons(port);
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (::connect(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0) return true;
    close();
    return false;
  }

  const std::string& response() const { return response_; }
  // The Sec-WebSocket-Protocol the server chose ("" if none).
  std::string protocol() const {
    const std::string key = "Sec-WebSocket-Protocol: ";
    const auto at = response_.find(key);
    if (at == std::string::npos) return {};
    return response_.substr(at + key.size(), response_.find("\r\n", at) - at - key.size());
  }

  void set_timeout(std::chrono::milliseconds t) {
    timeval tv{static_cast<time_t>(t.count() / 1000), static_cast<suseconds_t>((t.count() % 1000) * 1000)};
    ::setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
    ::setsockopt(fd_, SOL_SOCKET, SO_SNDTIMEO, &tv, sizeof tv);
  }

  bool send_text(const std::string& text) { return send_frame(0x1, text); }
  bool send_binary(const std::string& data) { return send_frame(0x2, data); }
  // A close frame with `payload` (a status code and reason, or nothing).
  bool send_close(const std::string& payload) { return send_frame(0x8, payload); }

  struct Frame {
    int opcode = 0;  // 1 text, 2 binary, 8 close
    std::string data;
  };
  // The next data or close frame (pings are answered); nullopt on timeout, EOF or error.
  std::optional<Frame> read() {
    Frame f;
    if (!read(f)) return std::nullopt;
    return f;
  }
  // The same into `f`, reusing its buffer (a reader of many frames allocates once); false on
  // timeout, EOF or error.
  bool read(Frame& f) {
    while (true) {
      unsigned char h[2];
      if (!read_all(h, 2)) return false;
      const int opcode = h[0] & 0x0f;
      std::uint64_t len = h[1] & 0x7f;
      if (len == 126) {
        unsigned char e[2];
        if (!read_all(e, 2)) return false;
        len = (std::uint64_t{e[0]} << 8) | e[1];
      } else if (len == 127) {
        unsigned char e[8];
        if (!read_all(e, 8)) return false;
        len = 0;
        for (unsigned char b : e) len = (len << 8) | b;
      }
      if (len > (64u << 20)) return false;
      f.opcode = opcode;
      f.data.resize(len);
      if (len > 0 && !read_all(f.data.data(), len)) return false;
      if (opcode == 0x9) {
        send_frame(0xA, f.data);
        continue;
      }
      if (opcode == 0xA) continue;
      return true;
    }
  }

  void close() {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
  }
  int fd() const { return fd_; }

 private:
  bool send_frame(int opcode, const std::string& data) {
    std::string f;
    f.push_back(static_cast<char>(0x80 | opcode));
    const std::uint64_t n = data.size();
    if (n < 126) {
      f.push_back(static_cast<char>(0x80 | n));
    } else if (n < 65536) {
      f.push_back(static_cast<char>(0x80 | 126));
      f.push_back(static_cast<char>(n >> 8));
      f.push_back(static_cast<char>(n & 0xff));
    } else {
      f.push_back(static_cast<char>(0x80 | 127));
      for (int i = 7; i >= 0; --i) f.push_back(static_cast<char>((n >> (8 * i)) & 0xff));
    }
    const unsigned char mask[4] = {0x12, 0x34, 0x56, 0x78};
    f.append(reinterpret_cast<const char*>(mask), 4);
    for (std::size_t i = 0; i < data.size(); ++i) f.push_back(static_cast<char>(data[i] ^ mask[i % 4]));
    return write_all(f.data(), f.size());
  }
  bool write_all(const char* p, std::size_t n) {
    while (n > 0) {
      const ssize_t w = ::send(fd_, p, n, MSG_NOSIGNAL);
      if (w <= 0) return false;
      p += w;
      n -= static_cast<std::size_t>(w);
    }
    return true;
  }
  bool read_all(void* out, std::size_t n) {
    auto* p = static_cast<char*>(out);
    while (n > 0) {
      const ssize_t r = ::recv(fd_, p, n, 0);
      if (r <= 0) return false;
      p += r;
      n -= static_cast<std::size_t>(r);
    }
    return true;
  }

  int fd_ = -1;
  std::string response_;
};

}  // namespace rbsim::foxglove::test
