// websocketpp + standalone asio behind transport.hpp. Compiled as C++17 (see CMakeLists.txt).
// Everything here runs on the one I/O thread, except wake() and stop(), which post to it.
#include "transport.hpp"

#include <websocketpp/config/asio.hpp>
#include <websocketpp/config/asio_no_tls.hpp>
#include <websocketpp/server.hpp>

#include <sys/eventfd.h>
#include <sys/stat.h>
#include <unistd.h>

#include <asio/posix/stream_descriptor.hpp>
#include <atomic>
#include <map>
#include <mutex>
#include <set>
#include <thread>
#include <type_traits>

namespace rbsim::foxglove::detail {

namespace {

using Hdl = websocketpp::connection_hdl;

// Config: websocketpp::config::asio (ws://) or asio_tls (wss://, options.tls_cert and tls_key).
template <class Config>
class AsioTransport final : public Transport {
  using WsServer = websocketpp::server<Config>;
  using ConPtr = typename WsServer::connection_ptr;

 public:
  ~AsioTransport() override { stop(); }

  std::string listen(const TransportOptions& options, TransportHandlers handlers) override {
    handlers_ = std::move(handlers);
    tick_ = std::chrono::milliseconds(options.tick_ms);
    const std::string& address = options.address;
    // websocketpp logs to stdout by default; the server reports what matters itself.
    ws_.clear_access_channels(websocketpp::log::alevel::all);
    ws_.clear_error_channels(websocketpp::log::elevel::all);
    websocketpp::lib::error_code ec;
    ws_.init_asio(&io_, ec);
    if (ec) return ec.message();
    // Lets a restarted server take its port while old connections sit in TIME_WAIT (on Linux it
    // does not let two servers listen on one port: a second one still gets "address in use").
    if constexpr (std::is_same_v<Config, websocketpp::config::asio_tls>) {
      if (std::string err = tls_context(options); !err.empty()) return err;
    }
    ws_.set_reuse_addr(true);
    ws_.set_max_message_size(options.max_message_size);
    // A socket that never completes its opening handshake (one that connects and says nothing, or
    // dribbles its request) is closed this long after it was accepted. The request's header is
    // limited by websocketpp itself (http::max_header_size, 16,000 bytes: 431 beyond), and a
    // handshake has no body.
    ws_.set_open_handshake_timeout(options.handshake_timeout_ms);
    ws_.set_max_http_body_size(0);
    ws_.set_listen_backlog(64);
    // Per-step messages are small and come every step: with Nagle on, the kernel holds each one
    // until the previous segment is acknowledged, and the client's delayed ACK turns that into
    // bursts many steps apart. Set on the accepted socket (the init handler runs before accept).
    ws_.set_tcp_post_init_handler([this](Hdl h) {
      websocketpp::lib::error_code hec;
      ConPtr con = ws_.get_con_from_hdl(h, hec);
      if (hec) return;
      asio::error_code nec;
      con->get_raw_socket().set_option(asio::ip::tcp::no_delay(true), nec);
    });
    ws_.set_validate_handler([this](Hdl h) { return validate(h); });
    ws_.set_open_handler([this](Hdl h) { opened(h); });
    ws_.set_close_handler([this](Hdl h) { closed(h); });
    ws_.set_fail_handler([this](Hdl h) { failed(h); });
    ws_.set_message_handler([this](Hdl h, typename WsServer::message_ptr m) {
      const auto it = ids_.find(h);
      if (it == ids_.end() || !handlers_.on_message) return;
      handlers_.on_message(it->second, m->get_payload(), m->get_opcode() != websocketpp::frame::opcode::text);
    });
    asio::error_code aec;
    const asio::ip::address ip = asio::ip::make_address(address, aec);
    if (aec) return "bad address \"" + address + "\": " + aec.message();
    const asio::ip::tcp::endpoint endpoint(ip, options.port);
    ws_.listen(endpoint, ec);
    if (ec) return bind_error(endpoint, ec.message());
    const asio::ip::tcp::endpoint local = ws_.get_local_endpoint(aec);
    if (aec) return aec.message();
    port_ = local.port();
    ws_.start_accept(ec);
    if (ec) return ec.message();
    listening_ = true;
    return {};
  }

  std::uint16_t port() const override { return port_; }

  void run() override {
    timer_ = std::make_unique<asio::steady_timer>(io_);
    arm_timer();
    // wake() writes to an eventfd the I/O thread reads: no allocation on the producer's thread
    // (an asio::post from outside the I/O thread allocates its handler every time).
    const int fd = ::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
    if (fd >= 0) {
      wake_fd_ = std::make_unique<asio::posix::stream_descriptor>(io_, fd);
      arm_wake();
    }
    thread_ = std::thread([this] {
      // A handler that throws (an allocation failure) must not take the process down with it
      // unseen: asio lets the exception out of run(); keep serving.
      while (true) {
        try {
          io_.run();
          break;
        } catch (const std::exception&) {
        }
      }
    });
  }

  void wake() override {
    if (wake_pending_.exchange(true)) return;
    if (wake_fd_) {
      const std::uint64_t one = 1;
      if (::write(wake_fd_->native_handle(), &one, sizeof one) == sizeof one) return;
    }
    asio::post(io_, [this] {  // no eventfd: the timer's tick would do, this is sooner
      wake_pending_ = false;
      if (handlers_.on_pump) handlers_.on_pump();
    });
  }

  void stop() override {
    std::lock_guard<std::mutex> lock(stop_mutex_);
    if (stopped_) return;
    stopped_ = true;
    if (thread_.joinable()) {
      asio::post(io_, [this] { shutdown(); });
      thread_.join();
    } else if (listening_) {
      shutdown();
      io_.run();  // let the cancelled accept finish
    }
  }

  bool send(ConnectionId id, std::string& data, bool binary) override {
    ConPtr con = find(id);
    if (!con) return false;
    // A prepared message is written as it is: websocketpp's own preparation would copy the
    // payload twice (into a message, then into a framed one). A server frame is unmasked and we
    // negotiate no extension, so the frame is the RFC 6455 header followed by the payload.
    // Once written, the message's buffer comes back to `spare_`, and from there to the caller:
    // buffers circulate instead of being freed and faulted in again for every message.
    std::shared_ptr<Message> msg(new Message(nullptr), [this](Message* m) {
      if (spare_.size() < kSpareMax) spare_.push_back(std::move(m->get_raw_payload()));
      delete m;
    });
    msg->set_opcode(binary ? websocketpp::frame::opcode::binary : websocketpp::frame::opcode::text);
    msg->set_header(frame_header(binary, data.size()));
    msg->get_raw_payload().swap(data);  // `data` now holds the new message's empty payload
    msg->set_prepared(true);
    if (!spare_.empty()) {
      data.swap(spare_.back());
      spare_.pop_back();
      data.clear();
    }
    return !con->send(msg);
  }

  std::size_t buffered(ConnectionId id) const override {
    ConPtr con = find(id);
    return con ? con->get_buffered_amount() : 0;
  }

  void drop(ConnectionId id) override {
    ConPtr con = find(id);
    if (!con) return;
    // A peer that does not read would never let a close frame through: close the socket, which
    // fails the pending read and write and makes websocketpp end the connection.
    asio::error_code ec;
    con->get_raw_socket().close(ec);
  }

 private:
  ConPtr find(ConnectionId id) const {
    const auto it = hdls_.find(id);
    if (it == hdls_.end()) return nullptr;
    websocketpp::lib::error_code ec;
    ConPtr con = const_cast<WsServer&>(ws_).get_con_from_hdl(it->second, ec);
    return ec ? nullptr : con;
  }

  // The header of an unmasked, final frame of `size` payload bytes (RFC 6455 section 5.2).
  static std::string frame_header(bool binary, std::size_t size) {
    std::string h;
    h.push_back(static_cast<char>(binary ? 0x82 : 0x81));
    if (size < 126) {
      h.push_back(static_cast<char>(size));
    } else if (size <= 0xFFFF) {
      h.push_back(static_cast<char>(126));
      for (int shift = 8; shift >= 0; shift -= 8) h.push_back(static_cast<char>((size >> shift) & 0xFF));
    } else {
      h.push_back(static_cast<char>(127));
      for (int shift = 56; shift >= 0; shift -= 8)
        h.push_back(static_cast<char>((static_cast<std::uint64_t>(size) >> shift) & 0xFF));
    }
    return h;
  }

  // One TLS context for every connection: TLS 1.2 or later, the certificate chain and key read
  // (and checked against each other) once, at listen.
  std::string tls_context(const TransportOptions& options) {
    auto ctx = std::make_shared<asio::ssl::context>(asio::ssl::context::tls_server);
    asio::error_code ec;
    ctx->set_options(asio::ssl::context::default_workarounds | asio::ssl::context::no_sslv2 |
                         asio::ssl::context::no_sslv3 | asio::ssl::context::no_tlsv1 |
                         asio::ssl::context::no_tlsv1_1 | asio::ssl::context::single_dh_use,
                     ec);
    if (!ec) SSL_CTX_set_min_proto_version(ctx->native_handle(), TLS1_2_VERSION);
    if (!ec) ctx->use_certificate_chain_file(options.tls_cert, ec);
    if (ec) return "TLS certificate " + options.tls_cert + ": " + ec.message();
    // The key is the server's identity: one any user of this host can read is refused (group
    // access is allowed: Debian's ssl-cert group holds keys at 0640).
    if (struct stat st{}; ::stat(options.tls_key.c_str(), &st) == 0 && (st.st_mode & S_IRWXO) != 0)
      return "TLS key " + options.tls_key +
             ": other users may read it; a private key must not be (chmod 600 " + options.tls_key + ")";
    ctx->use_private_key_file(options.tls_key, asio::ssl::context::pem, ec);
    if (ec) return "TLS key " + options.tls_key + ": " + ec.message();
    if (SSL_CTX_check_private_key(ctx->native_handle()) != 1)
      return "TLS key " + options.tls_key + " does not match the certificate " + options.tls_cert;
    ws_.set_tls_init_handler([ctx](Hdl) { return ctx; });
    return {};
  }

  // websocketpp reports a failed bind as "Underlying Transport Error"; a bind of our own says
  // what went wrong ("Address already in use").
  std::string bind_error(const asio::ip::tcp::endpoint& endpoint, const std::string& fallback) {
    asio::ip::tcp::acceptor probe(io_);
    asio::error_code ec;
    probe.open(endpoint.protocol(), ec);
    if (!ec) probe.set_option(asio::socket_base::reuse_address(true), ec);
    if (!ec) probe.bind(endpoint, ec);
    return ec ? ec.message() : fallback;
  }

  bool validate(Hdl h) {
    websocketpp::lib::error_code ec;
    ConPtr con = ws_.get_con_from_hdl(h, ec);
    if (ec) return false;
    if (handlers_.admit) {
      Handshake hs;
      asio::error_code aec;
      const asio::ip::tcp::endpoint remote = con->get_raw_socket().remote_endpoint(aec);
      if (!aec) {
        asio::ip::address a = remote.address();
        if (a.is_v6() && a.to_v6().is_v4_mapped())
          a = asio::ip::make_address_v4(asio::ip::v4_mapped, a.to_v6());
        hs.remote_address = a.to_string();
      }
      hs.resource = con->get_resource();
      hs.authorization = con->get_request_header("Authorization");
      hs.admitted = admitted_.size();
      const Admission verdict = handlers_.admit(hs);
      if (verdict.status != 0) {
        con->set_status(static_cast<websocketpp::http::status_code::value>(verdict.status));
        if (verdict.status == 401) con->append_header("WWW-Authenticate", "Bearer realm=\"rbsim\"");
        if (verdict.status == 429 || verdict.status == 503) con->append_header("Retry-After", "10");
        con->set_body(verdict.body);
        return false;
      }
    }
    const std::string chosen =
        handlers_.choose_subprotocol ? handlers_.choose_subprotocol(con->get_requested_subprotocols()) : "";
    if (chosen.empty()) {
      if (handlers_.on_refused) handlers_.on_refused();
      con->set_status(websocketpp::http::status_code::bad_request);
      con->set_body(
          "rbsim: a Foxglove WebSocket client must offer the subprotocol foxglove.sdk.v1 or "
          "foxglove.websocket.v1\n");
      return false;
    }
    con->select_subprotocol(chosen, ec);
    if (ec) return false;
    admitted_.insert(h);
    return true;
  }

  void failed(Hdl h) {
    websocketpp::lib::error_code ec;
    ConPtr con = ws_.get_con_from_hdl(h, ec);
    if (!ec &&
        con->get_ec() == websocketpp::error::make_error_code(websocketpp::error::open_handshake_timeout) &&
        handlers_.on_handshake_timeout) {
      handlers_.on_handshake_timeout();
    }
    closed(h);
  }

  void opened(Hdl h) {
    const ConnectionId id = next_id_++;
    ids_.emplace(h, id);
    hdls_.emplace(id, h);
    if (handlers_.on_open) handlers_.on_open(id);
  }

  void closed(Hdl h) {
    admitted_.erase(h);
    const auto it = ids_.find(h);
    if (it == ids_.end()) return;  // a failed handshake: never opened
    const ConnectionId id = it->second;
    ids_.erase(it);
    hdls_.erase(id);
    if (handlers_.on_close) handlers_.on_close(id);
  }

  void arm_wake() {
    wake_fd_->async_read_some(asio::buffer(&wake_count_, sizeof wake_count_),
                              [this](const asio::error_code& ec, std::size_t) {
                                if (ec || shutting_down_) return;
                                wake_pending_ = false;
                                if (handlers_.on_pump) handlers_.on_pump();
                                arm_wake();
                              });
  }

  void arm_timer() {
    timer_->expires_after(tick_);
    timer_->async_wait([this](const asio::error_code& ec) {
      if (ec || shutting_down_) return;
      if (handlers_.on_pump) handlers_.on_pump();
      arm_timer();
    });
  }

  void shutdown() {
    shutting_down_ = true;
    if (timer_) timer_->cancel();
    if (wake_fd_) {
      asio::error_code ec2;
      wake_fd_->close(ec2);
    }
    websocketpp::lib::error_code ec;
    if (listening_) ws_.stop_listening(ec);
    // Close every connection; a peer that does not answer the close is dropped by websocketpp's
    // close-handshake timeout. Then nothing is left for io_.run() and the thread ends.
    for (const auto& entry : hdls_) {
      ConPtr con = ws_.get_con_from_hdl(entry.second, ec);
      if (ec) continue;
      if (con->get_buffered_amount() > 0) {
        asio::error_code aec;
        con->get_raw_socket().close(aec);  // a backlog would hold the close frame back
      } else {
        con->close(websocketpp::close::status::going_away, "server stopping", ec);
      }
    }
    // A peer that does not answer the close within 500 ms is dropped (websocketpp would wait
    // 5 s), so Ctrl-C ends the command promptly.
    timer_ = std::make_unique<asio::steady_timer>(io_);
    timer_->expires_after(std::chrono::milliseconds(500));
    timer_->async_wait([this](const asio::error_code& ec2) {
      if (ec2) return;
      for (const auto& entry : hdls_) drop(entry.first);
    });
  }

  using Message = typename Config::message_type;
  static constexpr std::size_t kSpareMax = 64;
  // Buffers of written messages (I/O thread). Declared before ws_, whose connections may still
  // hold messages when it is destroyed.
  std::vector<std::string> spare_;
  asio::io_context io_;
  WsServer ws_;
  TransportHandlers handlers_;
  std::chrono::milliseconds tick_{10};
  std::unique_ptr<asio::steady_timer> timer_;
  std::thread thread_;
  std::atomic<bool> wake_pending_{false};
  std::unique_ptr<asio::posix::stream_descriptor> wake_fd_;
  std::uint64_t wake_count_ = 0;
  std::mutex stop_mutex_;
  bool stopped_ = false, listening_ = false, shutting_down_ = false;
  std::uint16_t port_ = 0;
  ConnectionId next_id_ = 1;
  std::map<Hdl, ConnectionId, std::owner_less<Hdl>> ids_;
  std::map<ConnectionId, Hdl> hdls_;
  // Handshakes admitted (validated) and not closed yet: the opened connections and those whose
  // answer is being written, so two handshakes at once cannot both take the last place.
  std::set<Hdl, std::owner_less<Hdl>> admitted_;
};

}  // namespace

std::unique_ptr<Transport> Transport::create(bool tls) {
  if (tls) return std::make_unique<AsioTransport<websocketpp::config::asio_tls>>();
  return std::make_unique<AsioTransport<websocketpp::config::asio>>();
}

}  // namespace rbsim::foxglove::detail
