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

struct TransportHandlers {
  // Handshake: the client's offered subprotocols -> the one to answer, or "" to refuse.
  std::function<std::string(const std::vector<std::string>& offered)> choose_subprotocol;
  std::function<void(ConnectionId)> on_open;
  std::function<void(ConnectionId, const std::string& payload, bool binary)> on_message;
  std::function<void(ConnectionId)> on_close;
  // Every tick_ms and after every wake(), on the I/O thread.
  std::function<void()> on_pump;
  std::function<void()> on_refused;  // a handshake was refused
};

// Every call but wake() and stop() is made on the I/O thread (from a handler).
class Transport {
 public:
  // Listens on address:port; "" on success, else why not ("address already in use").
  static std::unique_ptr<Transport> create();
  virtual ~Transport() = default;
  virtual std::string listen(const std::string& address, std::uint16_t port, std::size_t max_message_size,
                             int tick_ms, TransportHandlers handlers) = 0;
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
