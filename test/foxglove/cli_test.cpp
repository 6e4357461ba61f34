// --foxglove through the real rbsim binary: usage errors name the option and exit 2, a port in use
// exits 1 saying so, port 0 prints the port it took, the link and the layout; a node serves a
// client end to end. (DDS on rbsim's loopback configuration, on domain 61, which no other test
// uses; each test has its own namespace.)
#include <gtest/gtest.h>

#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include <poll.h>
#include <sys/stat.h>
#include <sys/wait.h>

#include <algorithm>
#include <csignal>
#include <cstring>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <thread>

#include "rbsim/subprocess.hpp"
#include "ws_client.hpp"

namespace rbsim {
namespace {

// The services a node's Foxglove server (and a bridge to it) offers, in order: the controls, then
// simulation_interfaces' (node/sim's list).
std::vector<std::string> node_services(const std::string& node) {
  std::vector<std::string> out;
  for (const char* name : {"pause",
                           "resume",
                           "reset",
                           "step",
                           "apply_impulse",
                           "get_simulator_features",
                           "get_simulation_state",
                           "set_simulation_state",
                           "reset_simulation",
                           "step_simulation",
                           "get_entities",
                           "get_entities_states",
                           "get_entity_info",
                           "get_entity_state",
                           "get_entity_bounds",
                           "set_entity_state",
                           "spawn_entity",
                           "spawn_entities",
                           "delete_entity",
                           "get_spawnables",
                           "load_world",
                           "unload_world",
                           "get_current_world",
                           "get_available_worlds"})
    out.push_back(node + "/" + name);
  return out;
}

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

// An rbsim command running in the background with --foxglove 0; its port is read from the
// listening line. Stopped with SIGINT (as Ctrl-C) at the end of the scope; every wait is bounded.
class Child {
 public:
  explicit Child(std::vector<std::string> args) {
    int fds[2];
    if (::pipe(fds) != 0) return;
    pid_ = ::fork();
    if (pid_ == 0) {
      ::dup2(fds[1], 2);
      ::close(fds[0]);
      ::close(fds[1]);
      std::vector<char*> argv{const_cast<char*>(RBSIM_EXE)};
      for (std::string& a : args) argv.push_back(a.data());
      argv.push_back(nullptr);
      ::execv(RBSIM_EXE, argv.data());
      ::_exit(127);
    }
    ::close(fds[1]);
    err_fd_ = fds[0];
  }
  ~Child() {
    (void)stop();
    if (err_fd_ >= 0) ::close(err_fd_);
  }
  // The port of "listening on ws://127.0.0.1:PORT" (0 if it did not come within 30 s).
  std::uint16_t port() {
    const std::regex listening("listening on ws://127\\.0\\.0\\.1:(\\d+)");
    std::smatch m;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
    while (!std::regex_search(err_, m, listening) && read_some(deadline)) {
    }
    return std::regex_search(err_, m, listening) ? static_cast<std::uint16_t>(std::stoi(m[1])) : 0;
  }
  // SIGINT, then the exit status (-1 if it had to be killed after 30 s) and everything it printed.
  int stop() {
    if (pid_ <= 0) return status_;
    ::kill(pid_, SIGINT);
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
    int st = 0;
    while (::waitpid(pid_, &st, WNOHANG) == 0) {
      if (std::chrono::steady_clock::now() > deadline) {
        ::kill(pid_, SIGKILL);
        ::waitpid(pid_, &st, 0);
        st = -1;
        break;
      }
      (void)read_some(std::chrono::steady_clock::now() + std::chrono::milliseconds(20));
    }
    while (read_some(std::chrono::steady_clock::now() + std::chrono::milliseconds(20))) {
    }
    pid_ = -1;
    status_ = st == -1 ? -1 : (WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st));
    return status_;
  }
  const std::string& err() const { return err_; }

 private:
  bool read_some(std::chrono::steady_clock::time_point deadline) {
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0 || err_fd_ < 0) return false;
    pollfd p{err_fd_, POLLIN, 0};
    if (::poll(&p, 1, static_cast<int>(left.count())) <= 0) return false;
    char buf[4096];
    const ssize_t n = ::read(err_fd_, buf, sizeof buf);
    if (n <= 0) return false;
    err_.append(buf, static_cast<std::size_t>(n));
    return true;
  }
  pid_t pid_ = -1;
  int err_fd_ = -1;
  int status_ = -1;
  std::string err_;
};

// What a viewer that subscribes to every channel sees in up to `frames` frames.
struct Seen {
  std::map<std::string, int> counts;               // messages per topic
  std::map<std::string, std::uint64_t> last_time;  // in the current session
  std::map<std::string, std::uint64_t> max_time;   // over all
  std::set<std::string> decreasing;                // topics whose log time went back within a session
  int server_infos = 0;                            // after the first
  std::set<std::string> sessions;
  int statuses = 0;
  nlohmann::json capabilities;        // the first serverInfo's
  std::vector<std::string> services;  // advertised
};
// Reads up to `frames` frames, or until every topic in `until` has arrived at least that often.
Seen watch(std::uint16_t port, int frames, const std::map<std::string, int>& until = {}) {
  Seen seen;
  foxglove::test::WsClient c;
  EXPECT_EQ(c.connect(port, {"foxglove.sdk.v1"}), 101);
  auto info = c.read();
  EXPECT_TRUE(info);
  if (!info) return seen;
  seen.sessions.insert(nlohmann::json::parse(info->data).value("sessionId", ""));
  seen.capabilities = nlohmann::json::parse(info->data).value("capabilities", nlohmann::json());
  auto adv = c.read();
  EXPECT_TRUE(adv);
  if (!adv) return seen;
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
    EXPECT_FALSE(ch.at("schema").get<std::string>().empty());
  }
  subscribe += "]}";
  EXPECT_TRUE(c.send_text(subscribe));
  for (int i = 0; i < frames; ++i) {
    auto f = c.read();
    if (!f) break;
    if (f->opcode == 1) {
      const auto j = nlohmann::json::parse(f->data, nullptr, false);
      if (j.value("op", "") == "serverInfo") {
        ++seen.server_infos;
        seen.sessions.insert(j.value("sessionId", ""));
        seen.last_time.clear();
      } else if (j.value("op", "") == "advertiseServices") {
        for (const auto& sv : j.at("services")) seen.services.push_back(sv.at("name").get<std::string>());
      } else {
        ++seen.statuses;
      }
      continue;
    }
    if (f->opcode != 2 || f->data.size() < 13 || f->data[0] != '\x01') continue;
    std::uint32_t sub = 0;
    std::uint64_t t = 0;
    std::memcpy(&sub, f->data.data() + 1, 4);
    std::memcpy(&t, f->data.data() + 5, 8);
    const std::string& topic = topic_of[sub];
    ++seen.counts[topic];
    if (seen.last_time.count(topic) > 0 && t < seen.last_time[topic]) seen.decreasing.insert(topic);
    seen.last_time[topic] = t;
    seen.max_time[topic] = std::max(seen.max_time[topic], t);
    if (!until.empty() && std::all_of(until.begin(), until.end(),
                                      [&](const auto& u) { return seen.counts[u.first] >= u.second; })) {
      break;
    }
  }
  return seen;
}

TEST(FoxgloveCli, NodeServesAClientEndToEnd) {
  Child node({"node", scene_path(), "--foxglove", "0", "--domain", kDomain, "--namespace", "fox_e2e",
              "--rate", "1", "--duration", "3"});
  const std::uint16_t port = node.port();
  ASSERT_GT(port, 0) << node.err();
  const Seen seen = watch(port, 400);
  EXPECT_EQ(node.stop(), 0) << node.err();
  EXPECT_EQ(seen.counts.at("/fox_e2e/scene"), 1);
  EXPECT_GT(seen.counts.at("/fox_e2e/body_states"), 10);
  EXPECT_GT(seen.counts.at("/clock"), 10);
  EXPECT_EQ(seen.counts.count("/fox_e2e/poses"), 0u) << "not a default topic";
  EXPECT_TRUE(seen.decreasing.empty()) << testing::PrintToString(seen.decreasing);
  EXPECT_GT(seen.max_time.at("/fox_e2e/body_states"), 0u);
  EXPECT_LE(seen.max_time.at("/fox_e2e/body_states"), 3'000'000'000ull) << "log time is simulated time";
  EXPECT_NE(node.err().find("rbsim node: stopped after"), std::string::npos) << node.err();
  EXPECT_NE(node.err().find("foxglove: 1 client,"), std::string::npos) << node.err();
  // Steered through its controller: parameters, the node's five services and simulation_interfaces'.
  EXPECT_EQ(seen.capabilities, nlohmann::json::array({"time", "parameters", "parametersSubscribe", "services",
                                                      "clientPublish"}));
  EXPECT_EQ(seen.services, node_services("/fox_e2e"));
}

// Binding an address other hosts reach without a token refuses to start, saying how to add one.
TEST(FoxgloveCli, AnAddressOtherHostsReachNeedsATokenOrInsecure) {
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"node", scene_path(), "--foxglove", "0.0.0.0:0", "--domain", kDomain,
                                 "--namespace", "fox_open", "--duration", "0.01", "--rate", "0"},
        std::vector<std::string>{"bridge", "--foxglove", "0.0.0.0:0", "--domain", kDomain, "--namespace",
                                 "fox_open"}}) {
    const test::Outcome o = rbsim(args, std::chrono::seconds(60));
    EXPECT_EQ(o.exit_code, 2) << o;
    EXPECT_NE(o.err.find("error: --foxglove 0.0.0.0:0 serves other hosts"), std::string::npos) << o;
    EXPECT_NE(o.err.find("--foxglove-token-file FILE"), std::string::npos) << o;
    EXPECT_NE(o.err.find("--foxglove-insecure"), std::string::npos) << o;
  }
  const test::Outcome insecure =
      rbsim({"node", scene_path(), "--foxglove", "0.0.0.0:0", "--foxglove-insecure", "--domain", kDomain,
             "--namespace", "fox_open", "--duration", "0.01", "--rate", "0"},
            std::chrono::seconds(60));
  EXPECT_EQ(insecure.exit_code, 0) << insecure;
  EXPECT_NE(insecure.err.find("listening on ws://0.0.0.0:"), std::string::npos) << insecure;
}

std::string write_token(const test::TempDir& dir, const std::string& name, const std::string& text,
                        mode_t mode) {
  const std::string path = (dir / name).string();
  std::ofstream(path) << text;
  ::chmod(path.c_str(), mode);
  return path;
}

TEST(FoxgloveCli, ABadTokenIsAUsageErrorNamingTheFileOrVariableAndTheRule) {
  test::TempDir dir;
  const std::string shared = write_token(dir, "shared", "0123456789abcdefgh\n", 0644);
  const std::string shorter = write_token(dir, "short", "0123456789\n", 0600);
  const std::vector<std::string> node{"node",       scene_path(), "--foxglove",  "0",
                                      "--domain",   kDomain,      "--namespace", "fox_token_bad",
                                      "--duration", "0.01",       "--rate",      "0"};
  for (const auto& [file, rule] :
       std::vector<std::pair<std::string, std::string>>{{shared, "chmod 600"},
                                                        {shorter, "at least 16 characters"},
                                                        {(dir / "none").string(), "No such file"}}) {
    std::vector<std::string> args = node;
    args.insert(args.end(), {"--foxglove-token-file", file});
    const test::Outcome o = rbsim(args, std::chrono::seconds(60));
    EXPECT_EQ(o.exit_code, 2) << o;
    EXPECT_NE(o.err.find("rbsim node: error: token file " + file), std::string::npos) << o;
    EXPECT_NE(o.err.find(rule), std::string::npos) << o;
  }
  const test::Outcome env =
      test::run_process(RBSIM_EXE, node, std::chrono::seconds(60), {"RBSIM_FOXGLOVE_TOKEN=short"});
  EXPECT_EQ(env.exit_code, 2) << env;
  EXPECT_NE(env.err.find("RBSIM_FOXGLOVE_TOKEN: a token must be at least 16"), std::string::npos) << env;
}

// A node with a token: clients without it get 401 (counted in the end line), with it they are
// served; the link carries the token only with --print-token.
TEST(FoxgloveCli, ATokenIsAskedAndPrintedOnlyWithPrintToken) {
  test::TempDir dir;
  const std::string token = "tok-0123456789-abcdef";
  const std::string file = write_token(dir, "token", token + "\n", 0600);
  {
    Child node({"node", scene_path(), "--foxglove", "0", "--foxglove-token-file", file, "--domain", kDomain,
                "--namespace", "fox_token", "--rate", "1", "--duration", "3"});
    const std::uint16_t port = node.port();
    ASSERT_GT(port, 0) << node.err();
    foxglove::test::WsClient without;
    EXPECT_EQ(without.connect(port, {"foxglove.websocket.v1"}), 401) << without.response();
    foxglove::test::WsClient with;
    ASSERT_EQ(with.connect(port, {"foxglove.websocket.v1"}, 0, "/?token=" + token), 101) << with.response();
    const auto info = with.read();
    ASSERT_TRUE(info);
    EXPECT_NE(info->data.find("serverInfo"), std::string::npos);
    with.close();
    EXPECT_EQ(node.stop(), 0) << node.err();
    EXPECT_NE(node.err().find("(token required: add /?token=TOKEN, or --print-token to print it)"),
              std::string::npos)
        << node.err();
    EXPECT_EQ(node.err().find(token), std::string::npos) << node.err();
    EXPECT_NE(node.err().find("foxglove: 1 client,"), std::string::npos) << node.err();
    EXPECT_NE(node.err().find(", 1 refused without the right token"), std::string::npos) << node.err();
  }
  const test::Outcome printed =
      test::run_process(RBSIM_EXE,
                        {"node", scene_path(), "--foxglove", "0", "--print-token", "--domain", kDomain,
                         "--namespace", "fox_token", "--duration", "0.01", "--rate", "0"},
                        std::chrono::seconds(60), {"RBSIM_FOXGLOVE_TOKEN=" + token});
  EXPECT_EQ(printed.exit_code, 0) << printed;
  EXPECT_NE(printed.err.find("%2F%3Ftoken%3D" + token + "\n"), std::string::npos) << printed;
}

// --foxglove-tls CERT KEY: wss:// in the listening line and the link; a certificate that cannot
// be read or a key that is not the certificate's is an error naming the file. (Clients over wss://:
// foxglove_client.tls.)
TEST(FoxgloveCli, TlsServesWssWithACertificateAndItsKey) {
  test::TempDir dir;
  const auto make = [&](const std::string& name) {
    const std::string cert = (dir / (name + ".crt")).string(), key = (dir / (name + ".key")).string();
    const test::Outcome o = test::run_process("/usr/bin/openssl",
                                              {"req", "-x509", "-newkey", "rsa:2048", "-nodes", "-keyout",
                                               key, "-out", cert, "-days", "1", "-subj", "/CN=127.0.0.1"},
                                              std::chrono::seconds(60));
    EXPECT_EQ(o.exit_code, 0) << o;
    return std::pair{cert, key};
  };
  const auto [cert, key] = make("a");
  const auto [other_cert, other_key] = make("b");
  const auto node = [&](const std::string& c, const std::string& k) {
    return rbsim({"node", scene_path(), "--foxglove", "0", "--foxglove-tls", c, k, "--domain", kDomain,
                  "--namespace", "fox_tls", "--duration", "0.01", "--rate", "0"},
                 std::chrono::seconds(60));
  };
  const test::Outcome ok = node(cert, key);
  EXPECT_EQ(ok.exit_code, 0) << ok;
  EXPECT_NE(ok.err.find("foxglove: listening on wss://127.0.0.1:"), std::string::npos) << ok;
  EXPECT_NE(ok.err.find("ds.url=wss%3A%2F%2F127.0.0.1%3A"), std::string::npos) << ok;
  const std::string missing = (dir / "missing.crt").string();
  const test::Outcome no_cert = node(missing, key);
  EXPECT_EQ(no_cert.exit_code, 1) << no_cert;
  EXPECT_NE(no_cert.err.find("cannot listen on wss://127.0.0.1:0: TLS certificate " + missing),
            std::string::npos)
      << no_cert;
  const test::Outcome mismatch = node(cert, other_key);
  EXPECT_EQ(mismatch.exit_code, 1) << mismatch;
  EXPECT_NE(mismatch.err.find("TLS key " + other_key + ": key values mismatch"), std::string::npos)
      << mismatch;
  std::filesystem::permissions(key, std::filesystem::perms::others_read, std::filesystem::perm_options::add);
  const test::Outcome exposed = node(cert, key);
  EXPECT_EQ(exposed.exit_code, 1) << exposed;
  EXPECT_NE(exposed.err.find("TLS key " + key + ": other users may read it"), std::string::npos) << exposed;
  const test::Outcome one = rbsim({"node", scene_path(), "--foxglove", "0", "--foxglove-tls", cert});
  EXPECT_EQ(one.exit_code, 2) << one;
  EXPECT_NE(one.err.find("--foxglove-tls"), std::string::npos) << one;
}

TEST(FoxgloveCli, ReplayServesARecordingWithANewSessionEveryLoop) {
  test::TempDir dir;
  const std::string log = (dir / "air.mcap").string();
  const test::Outcome rec = rbsim({"run", scene_path(), "--duration", "0.1", "--record", log});
  ASSERT_EQ(rec.exit_code, 0) << rec;
  Child replay({"replay", log, "--foxglove", "0", "--domain", kDomain, "--namespace", "fox_rp", "--rate",
                "0.5", "--loop"});
  const std::uint16_t port = replay.port();
  ASSERT_GT(port, 0) << replay.err();
  // 0.1 s of log at half speed: a pass every 0.2 s; watch a few.
  const Seen seen = watch(port, 3000, {{"/fox_rp/scene", 3}});
  EXPECT_EQ(replay.stop(), 0) << replay.err();
  EXPECT_GE(seen.counts.at("/fox_rp/scene"), 3) << "the scene again in every pass";
  EXPECT_GE(seen.server_infos, 2);
  EXPECT_GE(seen.sessions.size(), 3u) << "a new sessionId every pass";
  EXPECT_GT(seen.counts.at("/fox_rp/body_states"), 50);
  EXPECT_TRUE(seen.decreasing.empty())
      << "log times increase within a pass: " << testing::PrintToString(seen.decreasing);
  EXPECT_LE(seen.max_time.at("/fox_rp/body_states"), 100'000'000ull) << "log time is simulated time";
  EXPECT_NE(replay.err().find("rbsim replay: foxglove: open https://app.foxglove.dev/"), std::string::npos);
  EXPECT_EQ(seen.capabilities, nlohmann::json::array({"time", "services"}))
      << "the player's services, no parameters";
  EXPECT_EQ(seen.services.size(), 9u) << testing::PrintToString(seen.services);
  EXPECT_NE(std::find(seen.services.begin(), seen.services.end(), "/rbsim_player/seek"), seen.services.end());
}

TEST(FoxgloveCli, BridgeRelaysANodeOverDds) {
  Child bridge({"bridge", "--foxglove", "0", "--domain", kDomain, "--namespace", "fox_br"});
  const std::uint16_t port = bridge.port();
  ASSERT_GT(port, 0) << bridge.err();
  Child node({"node", scene_path(), "--domain", kDomain, "--namespace", "fox_br", "--rate", "1", "--duration",
              "20"});
  // Discovery matches each reader on its own: the scene may reach the bridge after the first body
  // states, so wait for both.
  const Seen seen = watch(port, 4000, {{"/fox_br/body_states", 100}, {"/fox_br/scene", 1}});
  EXPECT_EQ(node.stop(), 0) << node.err();
  EXPECT_EQ(bridge.stop(), 0) << bridge.err();
  EXPECT_GE(seen.counts.count("/fox_br/body_states") ? seen.counts.at("/fox_br/body_states") : 0, 100)
      << bridge.err();
  EXPECT_GE(seen.counts.count("/fox_br/scene") ? seen.counts.at("/fox_br/scene") : 0, 1)
      << "latched, via DDS";
  // Only the namespaced topics: /clock and /tf live at the root, where other nodes on the domain
  // (other tests) publish too.
  EXPECT_EQ(seen.decreasing.count("/fox_br/body_states"), 0u);
  if (seen.max_time.count("/fox_br/body_states") > 0) {
    EXPECT_LE(seen.max_time.at("/fox_br/body_states"), 20'000'000'000ull) << "log time is simulated time";
  }
  EXPECT_NE(bridge.err().find("rbsim bridge: stopped after"), std::string::npos) << bridge.err();
  // Steering relayed to the node's services (foxglove_client.bridge_steered uses it).
  for (const char* capability : {"parameters", "parametersSubscribe", "services", "clientPublish"}) {
    EXPECT_TRUE(std::find(seen.capabilities.begin(), seen.capabilities.end(), capability) !=
                seen.capabilities.end())
        << capability << " in " << seen.capabilities.dump();
  }
  EXPECT_EQ(seen.services, node_services("/fox_br"));  // simulation_interfaces' forwarded to the node
}

}  // namespace
}  // namespace rbsim
