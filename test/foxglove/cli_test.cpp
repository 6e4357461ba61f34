// --foxglove through the real rbsim binary: usage errors name the option and exit 2, a port in use
// exits 1 saying so, port 0 prints the port it took, the link and the layout; a node serves a
// client end to end. (DDS on rbsim's loopback configuration, on domain 61, which no other test
// uses; each test has its own namespace.)
#include <gtest/gtest.h>

#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include <sys/wait.h>

#include <csignal>
#include <cstring>
#include <map>
#include <regex>
#include <thread>

#include "rbsim/subprocess.hpp"
#include "ws_client.hpp"

namespace rbsim {
namespace {

using test::rbsim;
constexpr const char* kDomain = "61";

std::string scene_path() {
  return std::string(RBSIM_SOURCE_DIR) + "/scenes/airplane.xml";
}

struct Bad {
  std::vector<std::string> args;
  std::string first_line;
  std::string mentions;
};

TEST(FoxgloveCli, BadAddressesAreUsageErrorsNamingTheOption) {
  const std::string scene = scene_path();
  for (const Bad& c : std::vector<Bad>{
           {{"node", scene, "--foxglove", "abc"}, "rbsim node: error: --foxglove", "[ADDR:]PORT"},
           {{"node", scene, "--foxglove", "70000"}, "rbsim node: error: --foxglove", "out of range"},
           {{"node", scene, "--foxglove", "1.2.3:80"},
            "rbsim node: error: --foxglove",
            "not an IPv4 address"},
           {{"node", scene, "--foxglove", "localhost:"}, "rbsim node: error: --foxglove", "[ADDR:]PORT"},
           {{"node", scene, "--foxglove"}, "rbsim node: error: --foxglove", "1 required [ADDR:]PORT missing"},
           {{"replay", "x.mcap", "--foxglove", "[::1]"}, "rbsim replay: error: --foxglove", "[IPv6]:PORT"},
           {{"bridge"}, "rbsim bridge: error:", "--foxglove"},
           {{"bridge", "--foxglove", "host:1"}, "rbsim bridge: error: --foxglove", "IPv4"},
           {{"bridge", "--foxglove", "8765", "--namespace", "9x"},
            "rbsim bridge: error: --namespace",
            "digit"},
       }) {
    const test::Outcome o = rbsim(c.args, std::chrono::seconds(30));
    EXPECT_EQ(o.exit_code, 2) << o;
    ASSERT_FALSE(o.err_lines().empty()) << o;
    EXPECT_EQ(o.err_lines()[0].rfind(c.first_line, 0), 0u) << o;
    EXPECT_NE(o.err.find(c.mentions), std::string::npos) << o;
  }
}

TEST(FoxgloveCli, HelpShowsTheOption) {
  for (const char* command : {"node", "replay", "bridge"}) {
    const test::Outcome o = rbsim({command, "--help"});
    EXPECT_EQ(o.exit_code, 0) << o;
    EXPECT_NE(o.out.find("--foxglove"), std::string::npos) << o;
    EXPECT_NE(o.out.find("Exit status"), std::string::npos) << o;
  }
}

// A port another socket listens on.
struct Listener {
  int fd = -1;
  std::uint16_t port = 0;
  Listener() {
    fd = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    ::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a);
    ::listen(fd, 1);
    socklen_t len = sizeof a;
    ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len);
    port = ntohs(a.sin_port);
  }
  ~Listener() { ::close(fd); }
};

TEST(FoxgloveCli, APortInUseIsAnError) {
  Listener busy;
  ASSERT_GT(busy.port, 0);
  const test::Outcome o =
      rbsim({"node", scene_path(), "--foxglove", "127.0.0.1:" + std::to_string(busy.port), "--domain",
             kDomain, "--namespace", "fox_busy", "--duration", "0.01", "--rate", "0"},
            std::chrono::seconds(60));
  EXPECT_EQ(o.exit_code, 1) << o;
  EXPECT_NE(o.err.find("rbsim node: error: cannot listen on ws://127.0.0.1:" + std::to_string(busy.port)),
            std::string::npos)
      << o;
  EXPECT_NE(o.err.find("in use"), std::string::npos) << o;
}

TEST(FoxgloveCli, PortZeroPrintsThePortTheLinkAndTheLayout) {
  const test::Outcome o = rbsim({"node", scene_path(), "--foxglove", "0", "--domain", kDomain, "--namespace",
                                 "fox_zero", "--duration", "0.05", "--rate", "0"},
                                std::chrono::seconds(60));
  EXPECT_EQ(o.exit_code, 0) << o;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(o.err, m,
                                std::regex("rbsim node: foxglove: listening on ws://127\\.0\\.0\\.1:(\\d+)")))
      << o;
  const std::string port = m[1];
  EXPECT_NE(port, "0");
  EXPECT_NE(
      o.err.find(
          "foxglove: open https://app.foxglove.dev/?ds=foxglove-websocket&ds.url=ws%3A%2F%2F127.0.0.1%3A" +
          port + "\n"),
      std::string::npos)
      << o;
  EXPECT_NE(o.err.find("docs/foxglove-layout.json"), std::string::npos) << o;
  EXPECT_NE(o.err.find("foxglove: 0 clients"), std::string::npos) << o;
}

// The node serves a client: subscribes to every advertised channel, gets the scene (latched) and
// per-step messages at simulated times, and the node ends cleanly on SIGINT... here by --duration.
TEST(FoxgloveCli, NodeServesAClientEndToEnd) {
  // Port 0 in a child: read its port from the listening line while it runs.
  int pipe_fds[2];
  ASSERT_EQ(::pipe(pipe_fds), 0);
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    ::dup2(pipe_fds[1], 2);
    ::close(pipe_fds[0]);
    ::close(pipe_fds[1]);
    const std::string scene = scene_path();
    ::execl(RBSIM_EXE, RBSIM_EXE, "node", scene.c_str(), "--foxglove", "0", "--domain", kDomain,
            "--namespace", "fox_e2e", "--rate", "1", "--duration", "3", static_cast<char*>(nullptr));
    ::_exit(127);
  }
  ::close(pipe_fds[1]);
  std::string err;
  std::smatch m;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  const std::regex listening("listening on ws://127\\.0\\.0\\.1:(\\d+)");
  while (!std::regex_search(err, m, listening) && std::chrono::steady_clock::now() < deadline) {
    char buf[512];
    const ssize_t n = ::read(pipe_fds[0], buf, sizeof buf);
    if (n <= 0) break;
    err.append(buf, static_cast<std::size_t>(n));
  }
  ASSERT_TRUE(std::regex_search(err, m, listening)) << err;
  const auto port = static_cast<std::uint16_t>(std::stoi(m[1]));

  foxglove::test::WsClient c;
  ASSERT_EQ(c.connect(port, {"foxglove.sdk.v1"}), 101);
  auto info = c.read();
  ASSERT_TRUE(info);
  EXPECT_NE(info->data.find("\"serverInfo\""), std::string::npos);
  auto adv = c.read();
  ASSERT_TRUE(adv);
  const auto channels = nlohmann::json::parse(adv->data).at("channels");
  std::string subscribe = R"({"op":"subscribe","subscriptions":[)";
  std::map<std::uint32_t, std::string> topic_of;
  for (const auto& ch : channels) {
    const auto id = ch.at("id").get<std::uint32_t>();
    subscribe += (topic_of.empty() ? "" : ",") + std::string(R"({"id":)") + std::to_string(id) +
                 R"(,"channelId":)" + std::to_string(id) + "}";
    topic_of[id] = ch.at("topic").get<std::string>();
    EXPECT_EQ(ch.at("encoding"), "cdr");
    EXPECT_EQ(ch.at("schemaEncoding"), "ros2msg");
  }
  subscribe += "]}";
  ASSERT_TRUE(c.send_text(subscribe));
  std::map<std::string, int> counts;
  std::uint64_t last_states_time = 0;
  bool times_increase = true;
  for (int i = 0; i < 400; ++i) {
    auto f = c.read();
    if (!f) break;
    if (f->opcode != 2 || f->data.empty() || f->data[0] != '\x01') continue;
    std::uint32_t sub = 0;
    std::uint64_t t = 0;
    std::memcpy(&sub, f->data.data() + 1, 4);
    std::memcpy(&t, f->data.data() + 5, 8);
    ++counts[topic_of[sub]];
    if (topic_of[sub] == "/fox_e2e/body_states") {
      if (t < last_states_time) times_increase = false;
      last_states_time = t;
    }
  }
  c.close();
  ::kill(pid, SIGINT);
  int status = 0;
  ::waitpid(pid, &status, 0);
  ::close(pipe_fds[0]);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << status;
  EXPECT_EQ(counts["/fox_e2e/scene"], 1);
  EXPECT_GT(counts["/fox_e2e/body_states"], 10);
  EXPECT_GT(counts["/clock"], 10);
  EXPECT_EQ(counts.count("/fox_e2e/poses"), 0u) << "not a default topic";
  EXPECT_TRUE(times_increase);
  EXPECT_GT(last_states_time, 0u);
  EXPECT_LT(last_states_time, 3'000'000'001ull) << "log time is simulated time";
}

}  // namespace
}  // namespace rbsim
