// Who may connect to the Foxglove server, over real sockets on 127.0.0.1 (ws_client.hpp): the
// token (none or wrong: 401; right, in the query or an Authorization header: serverInfo), the
// per-address failure limit (429), the client limit (503), the handshake timeout (sockets that
// never speak are closed while a client keeps receiving), the header size limit, an address other
// hosts reach refused without a token; and the pure rules (token files, loopback, presented
// tokens). Every wait is bounded.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <sys/socket.h>
#include <sys/stat.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <fstream>
#include <thread>

#include "access.hpp"
#include "rbsim/foxglove.hpp"
#include "rbsim/subprocess.hpp"
#include "ws_client.hpp"

namespace rbsim::foxglove {
namespace {

using test::WsClient;
using Clock = std::chrono::steady_clock;
const std::string kToken = "s3cret-token_0123456789";
const std::vector<std::string> kProto{"foxglove.websocket.v1"};

std::unique_ptr<Server> start_with(ServerOptions o) {
  o.address = "127.0.0.1";
  o.port = 0;
  std::vector<ChannelSpec> c(1);
  c[0].topic = "/t/states";
  c[0].schema_name = "rbsim_msgs/msg/BodyStates";
  c[0].schema = "uint64 step\n";
  auto s = Server::start(o, std::move(c));
  EXPECT_TRUE(s) << (s ? "" : s.error().message);
  return s ? std::move(s.value()) : nullptr;
}

ServerOptions with_token() {
  ServerOptions o;
  o.token = kToken;
  return o;
}

std::string first_op(WsClient& c) {
  auto f = c.read();
  if (!f || f->opcode != 1) return {};
  return nlohmann::json::parse(f->data, nullptr, false).value("op", "");
}

TEST(FoxgloveAccess, NoTokenOrAWrongOneIs401BeforeTheUpgrade) {
  auto server = start_with(with_token());
  ASSERT_TRUE(server);
  WsClient none;
  EXPECT_EQ(none.connect(server->port(), kProto), 401) << none.response();
  EXPECT_NE(none.response().find("WWW-Authenticate: Bearer"), std::string::npos) << none.response();
  // The body says why, and the server closes: no WebSocket after a 401.
  std::string rest;
  char buf[512];
  ssize_t n = 0;
  while ((n = ::recv(none.fd(), buf, sizeof buf, 0)) > 0) rest.append(buf, static_cast<std::size_t>(n));
  EXPECT_EQ(n, 0) << "closed, not timed out";
  EXPECT_NE(rest.find("needs its token"), std::string::npos) << rest;
  WsClient wrong_query;
  EXPECT_EQ(wrong_query.connect(server->port(), kProto, 0, "/?token=" + kToken + "x"), 401);
  WsClient wrong_header;
  EXPECT_EQ(wrong_header.connect(server->port(), kProto, 0, "/",
                                 "Authorization: Bearer " + kToken.substr(1) + "\r\n"),
            401);
  WsClient empty;
  EXPECT_EQ(empty.connect(server->port(), kProto, 0, "/?token="), 401);
  EXPECT_EQ(server->stats().unauthorized, 4u);
  EXPECT_EQ(server->stats().clients, 0u);
}

TEST(FoxgloveAccess, TheRightTokenInTheQueryOrTheHeaderConnects) {
  auto server = start_with(with_token());
  ASSERT_TRUE(server);
  WsClient query;
  ASSERT_EQ(query.connect(server->port(), kProto, 0, "/?a=1&token=" + kToken), 101) << query.response();
  EXPECT_EQ(first_op(query), "serverInfo");
  WsClient encoded;  // percent-encoded, as url_with_token writes it
  const std::string url = url_with_token("ws://127.0.0.1:1", kToken);
  ASSERT_EQ(encoded.connect(server->port(), kProto, 0, url.substr(url.find("/?"))), 101)
      << encoded.response();
  EXPECT_EQ(first_op(encoded), "serverInfo");
  WsClient header;
  ASSERT_EQ(header.connect(server->port(), kProto, 0, "/", "Authorization: Bearer " + kToken + "\r\n"), 101)
      << header.response();
  EXPECT_EQ(first_op(header), "serverInfo");
  EXPECT_EQ(server->stats().unauthorized, 0u);
}

TEST(FoxgloveAccess, TwoHundredFailuresThenTheRightTokenStillWorks) {
  ServerOptions o = with_token();
  o.auth_failures_max = 1000;  // the loopback tests share one address: the limit is tested below
  auto server = start_with(o);
  ASSERT_TRUE(server);
  for (int i = 0; i < 200; ++i) {
    WsClient c;
    ASSERT_EQ(c.connect(server->port(), kProto, 0, "/?token=wrong-" + std::to_string(i)), 401) << i;
  }
  WsClient right;
  ASSERT_EQ(right.connect(server->port(), kProto, 0, "/?token=" + kToken), 101) << right.response();
  EXPECT_EQ(first_op(right), "serverInfo");
  EXPECT_EQ(server->stats().unauthorized, 200u);
}

TEST(FoxgloveAccess, RepeatedFailuresFromAnAddressGet429UntilTheWindowPasses) {
  ServerOptions o = with_token();
  o.auth_failures_max = 5;
  o.auth_failure_window_s = 1.0;
  auto server = start_with(o);
  ASSERT_TRUE(server);
  const auto first = Clock::now();
  for (int i = 0; i < 5; ++i) {
    WsClient c;
    ASSERT_EQ(c.connect(server->port(), kProto, 0, "/?token=wrong"), 401) << i;
  }
  WsClient sixth;
  EXPECT_EQ(sixth.connect(server->port(), kProto, 0, "/?token=wrong"), 429) << sixth.response();
  WsClient right_too_soon;  // not even the right token gets through while limited
  EXPECT_EQ(right_too_soon.connect(server->port(), kProto, 0, "/?token=" + kToken), 429);
  ASSERT_LT(Clock::now() - first, std::chrono::milliseconds(900)) << "too slow to test the window";
  std::this_thread::sleep_until(first + std::chrono::milliseconds(1100));
  WsClient right;
  ASSERT_EQ(right.connect(server->port(), kProto, 0, "/?token=" + kToken), 101) << right.response();
  EXPECT_EQ(first_op(right), "serverInfo");
  EXPECT_EQ(server->stats().unauthorized, 5u);
  EXPECT_EQ(server->stats().rate_limited, 2u);
}

TEST(FoxgloveAccess, BeyondMaxClientsIs503AndAFreedPlaceServesAgain) {
  ServerOptions o;
  o.max_clients = 2;
  auto server = start_with(o);
  ASSERT_TRUE(server);
  WsClient a, b, c;
  ASSERT_EQ(a.connect(server->port(), kProto), 101);
  ASSERT_EQ(b.connect(server->port(), kProto), 101);
  EXPECT_EQ(c.connect(server->port(), kProto), 503) << c.response();
  EXPECT_NE(c.response().find("Retry-After"), std::string::npos);
  EXPECT_EQ(server->stats().full, 1u);
  a.close();
  int status = 0;  // the server sees the close soon: bounded retries
  for (int i = 0; i < 100 && status != 101; ++i) {
    WsClient d;
    status = d.connect(server->port(), kProto);
    if (status != 101) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  EXPECT_EQ(status, 101);
}

// 100 sockets that connect and never send a byte are closed after the handshake timeout, while
// an admitted client keeps receiving the time messages published meanwhile.
TEST(FoxgloveAccess, SilentSocketsAreClosedAfterTheHandshakeTimeoutWhileAClientKeepsReceiving) {
  ServerOptions o = with_token();
  o.handshake_timeout_s = 0.5;
  auto server = start_with(o);
  ASSERT_TRUE(server);
  WsClient client;
  ASSERT_EQ(client.connect(server->port(), kProto, 0, "/?token=" + kToken), 101);
  std::atomic<bool> done{false};
  std::atomic<int> times{0};
  std::thread producer([&] {
    for (std::uint64_t t = 1; !done && t < 100000; ++t) {
      server->time(t);
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
  });
  std::thread reader([&] {
    WsClient::Frame f;
    while (!done && client.read(f)) {
      if (f.opcode == 2 && !f.data.empty() && f.data[0] == '\x02') ++times;
    }
  });
  std::vector<WsClient> silent(100);
  const auto opened = Clock::now();
  for (auto& s : silent) {
    s.open_only(server->port());
    ASSERT_GE(s.fd(), 0);
  }
  int closed = 0;
  for (auto& s : silent) {  // each read ends at EOF (or a reset); the timeout is 3 s from opening
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(opened + std::chrono::seconds(3) -
                                                                            Clock::now());
    if (left.count() <= 0) break;
    s.set_timeout(left);
    char byte;
    const ssize_t r = ::recv(s.fd(), &byte, 1, 0);
    if (r == 0 || (r < 0 && errno == ECONNRESET)) ++closed;
  }
  const auto elapsed = Clock::now() - opened;
  EXPECT_EQ(closed, 100);
  EXPECT_GE(elapsed, std::chrono::milliseconds(400)) << "closed before the timeout";
  const int before = times.load();
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  done = true;
  producer.join();
  ::shutdown(client.fd(), SHUT_RDWR);  // ends the reader's wait at once
  reader.join();
  EXPECT_GT(before, 20) << "the client received while the silent sockets waited";
  EXPECT_GT(times.load(), before) << "and still receives after";
  EXPECT_EQ(server->stats().handshake_timeouts, 100u);
  EXPECT_EQ(server->stats().clients, 1u);
}

TEST(FoxgloveAccess, AnOversizedRequestHeaderIsRefused) {
  auto server = start_with({});
  ASSERT_TRUE(server);
  WsClient big;
  EXPECT_EQ(big.connect(server->port(), kProto, 0, "/", "X-Pad: " + std::string(16100, 'a') + "\r\n"), 431)
      << big.response().substr(0, 200);
  WsClient fine;  // a large header within the limit still connects
  EXPECT_EQ(fine.connect(server->port(), kProto, 0, "/", "X-Pad: " + std::string(8000, 'a') + "\r\n"), 101);
}

TEST(FoxgloveAccess, AnAddressOtherHostsReachNeedsATokenOrAllowInsecure) {
  ServerOptions o;
  o.address = "0.0.0.0";
  o.port = 0;
  auto refused = Server::start(o, {});
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error().code, ErrorCode::InvalidArgument);
  EXPECT_NE(refused.error().message.find("without a token"), std::string::npos) << refused.error().message;
  o.allow_insecure = true;
  EXPECT_TRUE(Server::start(o, {}));
  o.allow_insecure = false;
  o.token = kToken;
  EXPECT_TRUE(Server::start(o, {}));
  o.token = "short";
  EXPECT_FALSE(Server::start(o, {}));
}

TEST(FoxgloveAccess, LoopbackIs127Slash8AndColonColon1) {
  for (const char* a : {"127.0.0.1", "127.1.2.3", "::1", "::ffff:127.0.0.1"})
    EXPECT_TRUE(is_loopback(a)) << a;
  for (const char* a : {"0.0.0.0", "::", "10.0.0.1", "128.0.0.1", "192.168.1.1", "::ffff:10.0.0.1", "x"})
    EXPECT_FALSE(is_loopback(a)) << a;
}

TEST(FoxgloveAccess, PresentedTokens) {
  using detail::presented_token;
  EXPECT_EQ(presented_token("/?token=abc", ""), "abc");
  EXPECT_EQ(presented_token("/?x=1&token=a%2Bb%25&y=2", ""), "a+b%");
  EXPECT_EQ(presented_token("/", "Bearer abc"), "abc");
  EXPECT_EQ(presented_token("/", "bearer abc"), "abc");
  EXPECT_EQ(presented_token("/?token=q", "Bearer h"), "h");
  EXPECT_EQ(presented_token("/", "Basic abc"), std::nullopt);
  EXPECT_EQ(presented_token("/?notoken=abc", ""), std::nullopt);
  EXPECT_TRUE(detail::same_token("abc", "abc"));
  EXPECT_FALSE(detail::same_token("abc", "abd"));
  EXPECT_FALSE(detail::same_token("abc", "abcd"));
}

TEST(FoxgloveAccess, TokenFilesArePrivateLongEnoughAndLoseTheirNewline) {
  rbsim::test::TempDir dir;
  const auto write = [&](const std::string& name, const std::string& text, mode_t mode) {
    const std::string path = (dir / name).string();
    std::ofstream(path) << text;
    ::chmod(path.c_str(), mode);
    return path;
  };
  const auto good = read_token_file(write("good", kToken + "\n", 0600));
  ASSERT_TRUE(good) << good.error().message;
  EXPECT_EQ(good.value(), kToken);
  const auto crlf = read_token_file(write("crlf", kToken + "\r\n", 0400));
  ASSERT_TRUE(crlf);
  EXPECT_EQ(crlf.value(), kToken);
  const std::string shared = write("shared", kToken, 0640);
  const auto r1 = read_token_file(shared);
  ASSERT_FALSE(r1);
  EXPECT_NE(r1.error().message.find(shared), std::string::npos) << r1.error().message;
  EXPECT_NE(r1.error().message.find("chmod 600"), std::string::npos) << r1.error().message;
  const std::string shorter = write("short", "0123456789abcde\n", 0600);
  const auto r2 = read_token_file(shorter);
  ASSERT_FALSE(r2);
  EXPECT_NE(r2.error().message.find("at least 16 characters"), std::string::npos) << r2.error().message;
  EXPECT_NE(r2.error().message.find(shorter), std::string::npos);
  EXPECT_FALSE(read_token_file(write("space", "0123456789 abcdefgh", 0600)));
  const auto missing = read_token_file((dir / "missing").string());
  ASSERT_FALSE(missing);
  EXPECT_NE(missing.error().message.find("missing"), std::string::npos);
}

}  // namespace
}  // namespace rbsim::foxglove
