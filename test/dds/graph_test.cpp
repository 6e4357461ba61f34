// rbsim's processes on the ROS 2 graph, seen from outside by a plain Cyclone DDS participant (the
// C API, no rbsim wrapper): the ros_discovery_info entry (node name and namespace, and the GIDs of
// exactly the endpoints DDS discovery reports for the participant: DCPSPublication and
// DCPSSubscription), Jazzy's and Humble's GID formats, the participant's USER_DATA, /rosout, and
// the node names of the commands. The raw-CDR type carries the bytes; they are decoded here with
// the CDR cursor by the layout of the rmw_dds_common and rcl_interfaces .msg files.
#include <dds/dds.h>
#include <dds/ddsi/ddsi_serdata.h>
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "raw_serdata.hpp"
#include "rbsim/cdr.hpp"
#include "rbsim/dds.hpp"
#include "rbsim/dds_sink.hpp"
#include "rbsim/rosout.hpp"
#include "rbsim/type_hash.hpp"

extern char** environ;

namespace rbsim::node {
namespace {

using Guid = msgs::Guid;
using Clock = std::chrono::steady_clock;

struct NodeInfo {
  std::string ns, name;
  std::vector<std::vector<std::uint8_t>> readers, writers;
};
struct EntitiesInfo {
  std::vector<std::uint8_t> gid;
  std::vector<NodeInfo> nodes;
};

bool read_gid(msgs::CdrCursor& c, std::size_t size, std::vector<std::uint8_t>& out) {
  out.resize(size);
  for (auto& b : out) {
    if (!c.read(b)) return false;
  }
  return true;
}
bool read_gids(msgs::CdrCursor& c, std::size_t size, std::vector<std::vector<std::uint8_t>>& out) {
  std::uint32_t n = 0;
  if (!c.u32(n) || n > c.remaining()) return false;
  out.resize(n);
  for (auto& g : out) {
    if (!read_gid(c, size, g)) return false;
  }
  return true;
}
// rmw_dds_common/msg/ParticipantEntitiesInfo with Gid = char[gid_size].
std::optional<EntitiesInfo> decode_info(std::span<const std::byte> cdr, std::size_t gid_size) {
  if (!msgs::CdrCursor::plain_header(cdr)) return std::nullopt;
  msgs::CdrCursor c(cdr);
  EntitiesInfo info;
  std::uint32_t n = 0;
  if (!read_gid(c, gid_size, info.gid) || !c.u32(n) || n > c.remaining()) return std::nullopt;
  info.nodes.resize(n);
  for (NodeInfo& node : info.nodes) {
    std::string_view ns, name;
    if (!c.string(ns) || !c.string(name) || !read_gids(c, gid_size, node.readers) ||
        !read_gids(c, gid_size, node.writers))
      return std::nullopt;
    node.ns = std::string(ns);
    node.name = std::string(name);
  }
  if (c.remaining() > 3) return std::nullopt;  // only the final padding may follow
  return info;
}

struct LogInfo {
  std::int32_t sec = 0;
  std::uint32_t nanosec = 0;
  std::uint8_t level = 0;
  std::string name, msg, file, function;
  std::uint32_t line = 0;
};
std::optional<LogInfo> decode_log(std::span<const std::byte> cdr) {
  if (!msgs::CdrCursor::plain_header(cdr)) return std::nullopt;
  msgs::CdrCursor c(cdr);
  LogInfo log;
  std::string_view name, msg, file, function;
  if (!c.read(log.sec) || !c.u32(log.nanosec) || !c.read(log.level) || !c.string(name) || !c.string(msg) ||
      !c.string(file) || !c.string(function) || !c.u32(log.line))
    return std::nullopt;
  log.name = std::string(name);
  log.msg = std::string(msg);
  log.file = std::string(file);
  log.function = std::string(function);
  return log;
}

// A participant of the observer's own, and a raw-CDR reader of one topic on it.
class Observer {
 public:
  explicit Observer(std::uint32_t domain) {
    participant_ = dds_create_participant(domain, nullptr, nullptr);
    EXPECT_GT(participant_, 0) << dds_strretcode(participant_);
  }
  ~Observer() { dds_delete(participant_); }
  dds_entity_t participant() const { return participant_; }

  // A reliable, transient-local reader (late joiners get the writer's history).
  dds_entity_t reader(const char* topic_name, const char* type_name) {
    ddsi_sertype* type = make_raw_sertype(type_name);
    const dds_entity_t topic =
        dds_create_topic_sertype(participant_, topic_name, &type, nullptr, nullptr, nullptr);
    EXPECT_GT(topic, 0) << dds_strretcode(topic);
    dds_qos_t* qos = dds_create_qos();
    dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
    dds_qset_durability(qos, DDS_DURABILITY_TRANSIENT_LOCAL);
    dds_qset_history(qos, DDS_HISTORY_KEEP_ALL, 0);
    const dds_entity_t r = dds_create_reader(participant_, topic, qos, nullptr);
    dds_delete_qos(qos);
    EXPECT_GT(r, 0) << dds_strretcode(r);
    return r;
  }

  // Every sample available now, as bytes.
  static std::vector<std::vector<std::byte>> take(dds_entity_t reader) {
    std::vector<std::vector<std::byte>> out;
    for (int i = 0; i < 100000; ++i) {
      ddsi_serdata* d = nullptr;
      dds_sample_info_t info{};
      if (dds_takecdr(reader, &d, 1, &info, DDS_ANY_STATE) <= 0) break;
      if (info.valid_data) {
        const std::uint32_t size = ddsi_serdata_size(d);
        std::vector<std::byte> bytes(size);
        ddsi_serdata_to_ser(d, 0, size, bytes.data());
        out.push_back(std::move(bytes));
      }
      ddsi_serdata_unref(d);
    }
    return out;
  }

 private:
  dds_entity_t participant_ = 0;
};

// Polls `done` every 50 ms for at most `seconds`.
bool eventually(double seconds, const std::function<bool()>& done) {
  const auto deadline = Clock::now() + std::chrono::duration<double>(seconds);
  while (Clock::now() < deadline) {
    if (done()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return done();
}

// The GUIDs of the endpoints DDS discovery reports for participant `gid` (its first 16 bytes).
struct Endpoints {
  std::set<std::vector<std::uint8_t>> readers, writers;
  std::set<std::string> writer_topics;
  // Each writer's DDS type name and USER_DATA, by topic.
  std::map<std::string, std::pair<std::string, std::string>> writer_user_data;
};
Endpoints discovered_endpoints(dds_entity_t observer, const std::vector<std::uint8_t>& participant) {
  Endpoints out;
  for (const bool readers : {false, true}) {
    const dds_entity_t r = dds_create_reader(
        observer, readers ? DDS_BUILTIN_TOPIC_DCPSSUBSCRIPTION : DDS_BUILTIN_TOPIC_DCPSPUBLICATION, nullptr,
        nullptr);
    void* samples[256] = {};
    dds_sample_info_t infos[256];
    const dds_return_t n = dds_read(r, samples, infos, 256, 256);
    for (dds_return_t i = 0; i < n; ++i) {
      const auto* e = static_cast<const dds_builtintopic_endpoint_t*>(samples[i]);
      if (!infos[i].valid_data || infos[i].instance_state != DDS_IST_ALIVE) continue;
      if (std::memcmp(e->participant_key.v, participant.data(), 16) != 0) continue;
      std::vector<std::uint8_t> guid(e->key.v, e->key.v + 16);
      (readers ? out.readers : out.writers).insert(guid);
      if (!readers) {
        out.writer_topics.insert(e->topic_name);
        void* ud = nullptr;
        std::size_t size = 0;
        std::string user_data;
        if (e->qos != nullptr && dds_qget_userdata(e->qos, &ud, &size) && ud != nullptr) {
          user_data.assign(static_cast<const char*>(ud), size);
          dds_free(ud);
        }
        out.writer_user_data[e->topic_name] = {e->type_name, user_data};
      }
    }
    if (n > 0) dds_return_loan(r, samples, n);
    dds_delete(r);
  }
  return out;
}

std::set<std::vector<std::uint8_t>> guids_of(const std::vector<std::vector<std::uint8_t>>& gids) {
  std::set<std::vector<std::uint8_t>> out;
  for (const auto& g : gids) out.insert(std::vector<std::uint8_t>(g.begin(), g.begin() + 16));
  return out;
}

// The latest entry of the participant whose node is `name`, once it lists `writers` writers
// and `readers` readers.
std::optional<EntitiesInfo> wait_for_entry(dds_entity_t reader, std::size_t gid_size, const std::string& name,
                                           std::size_t writers, std::size_t readers, double seconds = 10) {
  std::optional<EntitiesInfo> found;
  eventually(seconds, [&] {
    for (const auto& cdr : Observer::take(reader)) {
      auto info = decode_info(cdr, gid_size);
      if (!info || info->nodes.size() != 1 || info->nodes[0].name != name) continue;
      found = info;
    }
    return found && found->nodes[0].writers.size() == writers && found->nodes[0].readers.size() == readers;
  });
  return found;
}

constexpr const char* kInfoType = "rmw_dds_common::msg::dds_::ParticipantEntitiesInfo_";

// A node with the DDS sink's writers, /rosout and one subscription: the entry lists each of them
// and nothing else the participant has (its ros_discovery_info writer), in `gid_size` bytes.
void check_entry_matches_discovery(std::uint32_t domain, std::size_t gid_size) {
  Observer observer(domain);
  const dds_entity_t info_reader = observer.reader("ros_discovery_info", kInfoType);
  auto participant = create_dds_participant(domain, NodeName{"/graph/test", "sim"});
  ASSERT_TRUE(participant.ok()) << participant.error().message;
  NodeOptions options;
  options.domain = domain;
  options.ns = "graph/test/sim";
  auto sink = DdsSink::create(participant.value(), options);
  ASSERT_TRUE(sink.ok()) << sink.error().message;
  auto rosout = Rosout::create(participant.value());
  ASSERT_TRUE(rosout.ok()) << rosout.error().message;
  const msgs::TopicSpec& spec = msgs::topic(msgs::TopicId::Clock);
  auto created = Subscription::create(participant.value(), spec, "/clock", qos_for(spec));
  ASSERT_TRUE(created.ok()) << created.error().message;
  auto sub = std::make_unique<Subscription>(std::move(created.value()));

  const std::size_t sink_writers = msgs::topic_ids(options.topics).size();
  auto info = wait_for_entry(info_reader, gid_size, "sim", sink_writers + 1, 1);
  ASSERT_TRUE(info.has_value()) << "no ros_discovery_info entry listing " << sink_writers + 1 << " writers";
  EXPECT_EQ(info->nodes[0].ns, "/graph/test");
  EXPECT_EQ(info->gid.size(), gid_size);
  // rmw_cyclonedds_cpp's GID: the GUID, zero-padded.
  for (const auto* gids : {&info->nodes[0].readers, &info->nodes[0].writers}) {
    for (const auto& g : *gids)
      EXPECT_TRUE(std::all_of(g.begin() + 16, g.end(), [](auto b) { return b == 0; }));
  }
  EXPECT_TRUE(std::all_of(info->gid.begin() + 16, info->gid.end(), [](auto b) { return b == 0; }));

  Endpoints seen;
  ASSERT_TRUE(eventually(10,
                         [&] {
                           seen = discovered_endpoints(observer.participant(), info->gid);
                           return seen.writers.size() == sink_writers + 2 && seen.readers.size() == 1;
                         }))
      << "DDS discovery: " << seen.writers.size() << " writers, " << seen.readers.size() << " readers";
  EXPECT_EQ(guids_of(info->nodes[0].readers), seen.readers);
  // Every writer but ros_discovery_info's own (rmw does not list it either).
  auto listed = guids_of(info->nodes[0].writers);
  EXPECT_EQ(listed.size(), sink_writers + 1);
  std::size_t unlisted = 0;
  for (const auto& w : seen.writers) unlisted += listed.count(w) == 0;
  EXPECT_EQ(unlisted, 1u);
  for (const auto& w : listed) EXPECT_EQ(seen.writers.count(w), 1u);
  EXPECT_TRUE(seen.writer_topics.count("ros_discovery_info") == 1 &&
              seen.writer_topics.count("rt/rosout") == 1);
  // Every writer's USER_DATA is rmw_cyclonedds_cpp's "typehash=RIHS01_<hex>;" of its type on
  // Jazzy (REP 2011, msgs::type_hash), nothing on Humble.
  for (const auto& [topic, typed] : seen.writer_user_data) {
    std::string ros_type = typed.first;  // "pkg::msg::dds_::Name_" -> "pkg/msg/Name"
    ros_type.replace(ros_type.find("::msg::dds_::"), 13, "/msg/");
    ros_type.pop_back();
    if (gid_size == 16) {
      const Result<std::string> hash = msgs::type_hash(ros_type);
      ASSERT_TRUE(hash.ok()) << ros_type;
      EXPECT_EQ(typed.second, "typehash=" + hash.value() + ";") << topic;
    } else {
      EXPECT_EQ(typed.second, "") << topic;
    }
  }

  // An endpoint that goes is unlisted.
  sub.reset();
  auto after = wait_for_entry(info_reader, gid_size, "sim", sink_writers + 1, 0);
  ASSERT_TRUE(after.has_value()) << "the subscription's reader stayed listed";
  EXPECT_TRUE(after->nodes[0].readers.empty());
}

class EnvVar {
 public:
  EnvVar(const char* name, const char* value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old;
    if (value != nullptr) {
      setenv(name, value, 1);
    } else {
      unsetenv(name);
    }
  }
  ~EnvVar() {
    if (old_) {
      setenv(name_, old_->c_str(), 1);
    } else {
      unsetenv(name_);
    }
  }

 private:
  const char* name_;
  std::optional<std::string> old_;
};

TEST(Graph, DiscoveryInfoListsTheEndpointsDiscoveryReportsJazzy) {
  EnvVar distro("ROS_DISTRO", nullptr);
  check_entry_matches_discovery(145, 16);
}

TEST(Graph, DiscoveryInfoListsTheEndpointsDiscoveryReportsHumble) {
  EnvVar distro("ROS_DISTRO", "humble");
  check_entry_matches_discovery(146, 24);
}

TEST(Graph, ParticipantThatGoesUnlistsItsNodeFirst) {
  constexpr std::uint32_t kDomain = 154;
  Observer observer(kDomain);
  const dds_entity_t reader = observer.reader("ros_discovery_info", kInfoType);
  std::vector<std::uint8_t> participant_gid;
  {
    auto participant = create_dds_participant(kDomain, NodeName{"/", "short_lived"});
    ASSERT_TRUE(participant.ok()) << participant.error().message;
    auto info = wait_for_entry(reader, 16, "short_lived", 0, 0);
    ASSERT_TRUE(info.has_value());
    participant_gid = info->gid;
  }
  std::optional<EntitiesInfo> last;
  eventually(10, [&] {
    for (const auto& cdr : Observer::take(reader)) {
      if (auto i = decode_info(cdr, 16); i && i->gid == participant_gid) last = i;
    }
    return last && last->nodes.empty();
  });
  ASSERT_TRUE(last.has_value());
  EXPECT_TRUE(last->nodes.empty()) << "the last entry still lists " << last->nodes.size() << " node(s)";
}

TEST(Graph, ParticipantUserDataCarriesTheEnclave) {
  constexpr std::uint32_t kDomain = 147;
  Observer observer(kDomain);
  auto participant = create_dds_participant(kDomain, NodeName{"/", "enclave_test"});
  ASSERT_TRUE(participant.ok()) << participant.error().message;
  dds_guid_t key{};
  ASSERT_EQ(dds_get_guid(dds_entity(participant.value()), &key), DDS_RETCODE_OK);
  std::optional<std::string> user_data;
  eventually(10, [&] {
    const dds_entity_t r =
        dds_create_reader(observer.participant(), DDS_BUILTIN_TOPIC_DCPSPARTICIPANT, nullptr, nullptr);
    void* samples[64] = {};
    dds_sample_info_t infos[64];
    const dds_return_t n = dds_read(r, samples, infos, 64, 64);
    for (dds_return_t i = 0; i < n; ++i) {
      const auto* p = static_cast<const dds_builtintopic_participant_t*>(samples[i]);
      if (!infos[i].valid_data || std::memcmp(p->key.v, key.v, 16) != 0) continue;
      void* ud = nullptr;
      std::size_t size = 0;
      if (dds_qget_userdata(p->qos, &ud, &size)) {
        user_data = std::string(static_cast<const char*>(ud), size);
        dds_free(ud);
      }
    }
    if (n > 0) dds_return_loan(r, samples, n);
    dds_delete(r);
    return user_data.has_value();
  });
  ASSERT_TRUE(user_data.has_value()) << "the participant was not discovered";
  EXPECT_EQ(*user_data, "enclave=/;");
}

TEST(Rosout, LogPublishesTheLineWithLevelNameAndSite) {
  constexpr std::uint32_t kDomain = 148;
  Observer observer(kDomain);
  const dds_entity_t reader = observer.reader("rt/rosout", "rcl_interfaces::msg::dds_::Log_");
  auto participant = create_dds_participant(kDomain, NodeName{"/a/b", "sim"});
  ASSERT_TRUE(participant.ok()) << participant.error().message;
  auto rosout = Rosout::create(participant.value(), [] { return std::int64_t{12'500'000'001}; });
  ASSERT_TRUE(rosout.ok()) << rosout.error().message;
  const std::uint32_t line = __LINE__ + 1;
  RBSIM_LOG(Warn, "rbsim test: %d warnings", 3);
  std::optional<LogInfo> got;
  eventually(10, [&] {
    for (const auto& cdr : Observer::take(reader)) got = decode_log(cdr);
    return got.has_value();
  });
  ASSERT_TRUE(got.has_value()) << "nothing on /rosout";
  EXPECT_EQ(got->level, 30);
  EXPECT_EQ(got->name, "a.b.sim");
  EXPECT_EQ(got->msg, "rbsim test: 3 warnings");
  EXPECT_EQ(got->sec, 12);
  EXPECT_EQ(got->nanosec, 500'000'001u);
  EXPECT_NE(got->file.find("graph_test.cpp"), std::string::npos) << got->file;
  EXPECT_EQ(got->function, "TestBody");
  EXPECT_EQ(got->line, line);
}

// ---------------------------------------------------------------------------------------------
// The commands, through the binary.

class Process {
 public:
  explicit Process(std::vector<std::string> args) {
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
    posix_spawn_file_actions_addopen(&actions, 2, "/dev/null", O_WRONLY, 0);
    EXPECT_EQ(posix_spawn(&pid_, argv[0], &actions, nullptr, argv.data(), environ), 0) << args[0];
    posix_spawn_file_actions_destroy(&actions);
  }
  ~Process() {
    if (pid_ <= 0) return;
    kill(pid_, SIGINT);
    int status = 0;
    for (int i = 0; i < 100 && waitpid(pid_, &status, WNOHANG) == 0; ++i) usleep(50'000);
    if (waitpid(pid_, &status, WNOHANG) == 0) {
      kill(pid_, SIGKILL);
      waitpid(pid_, &status, 0);
    }
  }

 private:
  pid_t pid_ = 0;
};

// The node name and namespace a command announces.
std::optional<std::pair<std::string, std::string>> announced(std::uint32_t domain,
                                                             std::vector<std::string> args,
                                                             const std::string& name) {
  Observer observer(domain);
  const dds_entity_t reader = observer.reader("ros_discovery_info", kInfoType);
  Process process(std::move(args));
  std::optional<std::pair<std::string, std::string>> found;
  eventually(15, [&] {
    for (const auto& cdr : Observer::take(reader)) {
      auto info = decode_info(cdr, 16);
      if (info && info->nodes.size() == 1 && info->nodes[0].name == name)
        found = {info->nodes[0].ns, info->nodes[0].name};
    }
    return found.has_value();
  });
  return found;
}

std::string tmp_path(const char* name) {
  return ::testing::TempDir() + "/rbsim_graph_" + std::to_string(getpid()) + "_" + name;
}

TEST(GraphCli, RecordIsRbsimRecorderAndNodeNameOverridesIt) {
  const std::string out = tmp_path("a.mcap");
  auto got = announced(149, {RBSIM_BINARY, "record", "--domain", "149", "--wall-duration", "20", out},
                       "rbsim_recorder");
  ASSERT_TRUE(got.has_value());
  EXPECT_EQ(got->first, "/");
  const std::string out2 = tmp_path("b.mcap");
  got = announced(
      150,
      {RBSIM_BINARY, "record", "--domain", "150", "--wall-duration", "20", "--node-name", "/tools/rec", out2},
      "rec");
  ASSERT_TRUE(got.has_value());
  EXPECT_EQ(got->first, "/tools");
}

TEST(GraphCli, ReplayIsRbsimPlayer) {
  const std::string recording = tmp_path("replay.mcap");
  const std::string run = std::string(RBSIM_BINARY) + " run " + RBSIM_SOURCE_DIR +
                          "/scenes/chain.xml --steps 20 --record " + recording +
                          " --overwrite > /dev/null 2>&1";
  ASSERT_EQ(std::system(run.c_str()), 0) << run;
  auto got = announced(153, {RBSIM_BINARY, "replay", recording, "--domain", "153", "--loop"}, "rbsim_player");
  ASSERT_TRUE(got.has_value());
  EXPECT_EQ(got->first, "/");
  std::remove(recording.c_str());
}

TEST(GraphCli, NodeNameThatIsNoRosNameIsAUsageError) {
  for (const char* bad : {"1recorder", "a//b", "rec-1", "/"}) {
    const std::string cmd = std::string(RBSIM_BINARY) + " record --node-name '" + bad + "' " +
                            tmp_path("bad.mcap") + " > /dev/null 2>&1";
    const int status = std::system(cmd.c_str());
    ASSERT_TRUE(WIFEXITED(status)) << cmd;
    EXPECT_EQ(WEXITSTATUS(status), 2) << cmd;
  }
}

TEST(GraphCli, BridgeIsRbsimBridge) {
  auto got = announced(151, {RBSIM_BINARY, "bridge", "--domain", "151", "--foxglove", "127.0.0.1:0"},
                       "rbsim_bridge");
  ASSERT_TRUE(got.has_value());
  EXPECT_EQ(got->first, "/");
}

TEST(GraphCli, NodeNamespaceIsTheNodeAndItsStartLineGoesToRosout) {
  constexpr std::uint32_t kDomain = 152;
  Observer observer(kDomain);
  const dds_entity_t rosout = observer.reader("rt/rosout", "rcl_interfaces::msg::dds_::Log_");
  const dds_entity_t info_reader = observer.reader("ros_discovery_info", kInfoType);
  Process node({RBSIM_BINARY, "node", std::string(RBSIM_SOURCE_DIR) + "/scenes/chain.xml", "--domain", "152",
                "--namespace", "robots/sim1", "--loop"});
  std::optional<LogInfo> start;
  std::optional<EntitiesInfo> info;
  eventually(15, [&] {
    for (const auto& cdr : Observer::take(rosout)) {
      auto log = decode_log(cdr);
      if (log && log->msg.starts_with("rbsim node: ")) start = start ? start : log;
    }
    for (const auto& cdr : Observer::take(info_reader)) {
      if (auto i = decode_info(cdr, 16); i && i->nodes.size() == 1) info = i;
    }
    return start && info;
  });
  ASSERT_TRUE(info.has_value()) << "no ros_discovery_info from rbsim node";
  EXPECT_EQ(info->nodes[0].ns, "/robots");
  EXPECT_EQ(info->nodes[0].name, "sim1");
  ASSERT_TRUE(start.has_value()) << "no start line on /rosout";
  EXPECT_EQ(start->level, 20);
  EXPECT_EQ(start->name, "robots.sim1");
  EXPECT_NE(start->msg.find("topics under /robots/sim1"), std::string::npos) << start->msg;
  EXPECT_EQ(start->sec, 0);  // simulated time: the node has not stepped yet
  EXPECT_EQ(start->function, "node_command");
}

}  // namespace
}  // namespace rbsim::node
