// The WebSocket transport under the Foxglove server: websocketpp + standalone asio, which compile
// as C++17 only (GCC 12 rejects websocketpp 0.8.2 under C++20), so they live in their own static
// library (rbsim_foxglove_transport) behind this header, which names none of their types and is
// valid C++17 and C++20 alike.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace rbsim::foxglove::detail {

using ConnectionId = std::uint64_t;

// What a handshake asks for, as the admission handler sees it (before the upgrade).
struct Handshake {
  std::string remote_address;  // "127.0.0.1", "::1" (an IPv4-mapped IPv6 address as IPv4)
  std::string resource;        // the request target: "/", "/?token=..."
  std::string authorization;   // the Authorization header ("" if none)
  std::size_t admitted = 0;    // connections admitted and not closed yet (this one not counted)
};
// The answer: status 0 admits; else the HTTP status (401, 429, 503) and body the handshake gets.
struct Admission {
  int status = 0;
  std::string body;
};

struct TransportOptions {
  std::string address;
  std::uint16_t port = 0;
  std::size_t max_message_size = 0;
  int tick_ms = 10;
  // A connection that has not completed its opening handshake this long after it was accepted is
  // closed.
  int handshake_timeout_ms = 5000;
  // wss:// (a transport created with tls): the PEM certificate chain and private key files.
  std::string tls_cert, tls_key;
};

struct TransportHandlers {
  // Handshake: the client's offered subprotocols -> the one to answer, or "" to refuse.
  std::function<std::string(const std::vector<std::string>& offered)> choose_subprotocol;
  // Before the subprotocol: admits or refuses the handshake with a status (unset: every one).
  std::function<Admission(const Handshake&)> admit;
  std::function<void(ConnectionId)> on_open;
  std::function<void(ConnectionId, const std::string& payload, bool binary)> on_message;
  std::function<void(ConnectionId)> on_close;
  // Every tick_ms and after every wake(), on the I/O thread.
  std::function<void()> on_pump;
  std::function<void()> on_refused;            // a handshake was refused for its subprotocols
  std::function<void()> on_handshake_timeout;  // a connection closed for not completing its handshake
};

// Every call but wake() and stop() is made on the I/O thread (from a handler).
class Transport {
 public:
  // Listens on address:port; "" on success, else why not ("address already in use").
  // `tls`: wss:// (TLS 1.2 or later; listen() reads TransportOptions' certificate and key).
  static std::unique_ptr<Transport> create(bool tls = false);
  virtual ~Transport() = default;
  virtual std::string listen(const TransportOptions& options, TransportHandlers handlers) = 0;
  virtual std::uint16_t port() const = 0;
  // Starts the I/O thread.
  virtual void run() = 0;
  // Any thread: run on_pump soon (coalesced: one pending wake at a time).
  virtual void wake() = 0;
  // Any thread: close every connection, stop listening, join the I/O thread.
  virtual void stop() = 0;

  // I/O thread only. Sends `data` as one WebSocket message, taking its buffer (no copy: the
  // frame header goes beside it in one gather write); `data` is left empty, holding the buffer of
  // an earlier message that has been written, when there is one. False when the connection is
  // gone.
  virtual bool send(ConnectionId id, std::string& data, bool binary) = 0;
  // Bytes handed to the socket layer and not yet written for `id` (0 when gone).
  virtual std::size_t buffered(ConnectionId id) const = 0;
  // Drops the connection at once (no close handshake: for a peer that does not read).
  virtual void drop(ConnectionId id) = 0;
};

}  // namespace rbsim::foxglove::detail
