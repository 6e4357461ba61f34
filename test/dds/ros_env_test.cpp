// ROS 2's environment variables onto the DDS domain and Cyclone configuration
// (rbsim/ros_env.hpp): the mapping as configuration text only. Only LOCALHOST and OFF
// configurations are ever used to start a participant here (loopback); SUBNET and
// SYSTEM_DEFAULT would discover on real interfaces, so they are checked as text.
#include <dds/dds.h>
#include <gtest/gtest.h>

#include <string>

#include "rbsim/dds.hpp"
#include "rbsim/ros_env.hpp"

namespace rbsim::node {
namespace {

constexpr std::int64_t kPid = 4242;

DdsSettings resolve_ok(const RosEnvironment& env, std::optional<std::uint32_t> domain = std::nullopt) {
  auto r = resolve_dds_settings(env, domain, kPid);
  EXPECT_TRUE(r.ok()) << (r.ok() ? "" : r.error().message);
  return r.ok() ? r.value() : DdsSettings{};
}

std::string resolve_error(const RosEnvironment& env, std::optional<std::uint32_t> domain = std::nullopt) {
  auto r = resolve_dds_settings(env, domain, kPid);
  EXPECT_FALSE(r.ok());
  return r.ok() ? "" : r.error().message;
}

bool has(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

TEST(RosEnv, NothingSetIsDomainZeroOnTheLoopbackConfigurationExactly) {
  const DdsSettings s = resolve_ok({});
  EXPECT_EQ(s.domain, 0u);
  EXPECT_EQ(s.range, DiscoveryRange::Localhost);
  ASSERT_TRUE(s.config.has_value());
  EXPECT_EQ(*s.config, loopback_config());
  EXPECT_TRUE(s.warnings.empty());
  EXPECT_EQ(s.describe(), "domain 0 (LOCALHOST)");
  // Empty values mean the same as unset (rcl).
  const DdsSettings e = resolve_ok({"", "", "", "", "", ""});
  EXPECT_EQ(e.domain, 0u);
  EXPECT_EQ(*e.config, loopback_config());
}

TEST(RosEnv, RosDomainIdChoosesTheDomainAndTheCommandLineWins) {
  RosEnvironment env;
  env.ros_domain_id = "7";
  EXPECT_EQ(resolve_ok(env).domain, 7u);
  EXPECT_EQ(*resolve_ok(env).config, loopback_config());
  EXPECT_EQ(resolve_ok(env, 3).domain, 3u);  // --domain 3
  env.ros_domain_id = "232";
  EXPECT_EQ(resolve_ok(env).domain, 232u);
  env.ros_domain_id = "abc";  // not even looked at when --domain is given (as rcl)
  EXPECT_EQ(resolve_ok(env, 5).domain, 5u);
}

TEST(RosEnv, BadDomainIdsAreOneLineErrorsNamingTheVariable) {
  for (const char* bad : {"abc", "-1", "7x", " 7", "0x7", "1e3", "99999999999999999999"}) {
    RosEnvironment env;
    env.ros_domain_id = bad;
    const std::string e = resolve_error(env);
    EXPECT_TRUE(has(e, "ROS_DOMAIN_ID='" + std::string(bad) + "' is not a DDS domain id")) << e;
    EXPECT_FALSE(has(e, "\n")) << e;
  }
  RosEnvironment env;
  env.ros_domain_id = "233";
  EXPECT_EQ(resolve_error(env), "ROS_DOMAIN_ID='233': domain id 233 out of range [0, 232]");
  EXPECT_EQ(resolve_error({}, 233), "domain id 233 out of range [0, 232]");
  auto alone = domain_from_environment(env);
  EXPECT_FALSE(alone.ok());
  env.ros_domain_id = "12";
  ASSERT_TRUE(domain_from_environment(env).ok());
  EXPECT_EQ(domain_from_environment(env).value(), std::optional<std::uint32_t>(12));
  EXPECT_EQ(domain_from_environment({}).value(), std::nullopt);
}

TEST(RosEnv, DiscoveryRanges) {
  RosEnvironment env;
  env.ros_automatic_discovery_range = "LOCALHOST";
  EXPECT_EQ(*resolve_ok(env).config, loopback_config());

  // SUBNET (rmw: no General settings: Cyclone's interface, multicast allowed; participant index auto).
  env.ros_automatic_discovery_range = "SUBNET";
  DdsSettings s = resolve_ok(env);
  EXPECT_EQ(s.range, DiscoveryRange::Subnet);
  ASSERT_TRUE(s.config);
  EXPECT_FALSE(has(*s.config, "NetworkInterface")) << *s.config;
  EXPECT_FALSE(has(*s.config, "AllowMulticast")) << *s.config;
  EXPECT_FALSE(has(*s.config, "<Peers>")) << *s.config;
  EXPECT_TRUE(has(*s.config, "<ParticipantIndex>auto</ParticipantIndex>")) << *s.config;
  EXPECT_EQ(s.describe(), "domain 0 (SUBNET)");

  // OFF (rmw: no multicast, participant index none, a discovery tag of this process; rbsim: loopback).
  env.ros_automatic_discovery_range = "OFF";
  s = resolve_ok(env);
  EXPECT_EQ(s.range, DiscoveryRange::Off);
  ASSERT_TRUE(s.config);
  EXPECT_TRUE(has(*s.config, "<AllowMulticast>false</AllowMulticast>")) << *s.config;
  EXPECT_TRUE(has(*s.config, "<ParticipantIndex>none</ParticipantIndex>")) << *s.config;
  EXPECT_TRUE(has(*s.config, "<Tag>ros_discovery_off_4242</Tag>")) << *s.config;
  EXPECT_TRUE(has(*s.config, R"(<NetworkInterface address="127.0.0.1"/>)")) << *s.config;
  EXPECT_FALSE(has(*s.config, "<Peers>")) << *s.config;

  // SYSTEM_DEFAULT: Cyclone's defaults, no configuration at all.
  env.ros_automatic_discovery_range = "SYSTEM_DEFAULT";
  s = resolve_ok(env);
  EXPECT_EQ(s.range, DiscoveryRange::SystemDefault);
  EXPECT_FALSE(s.config.has_value());

  for (const char* bad : {"localhost", "Subnet", "ALL", "NONE", "LOCALHOST "}) {
    env.ros_automatic_discovery_range = bad;
    EXPECT_EQ(resolve_error(env), "ROS_AUTOMATIC_DISCOVERY_RANGE='" + std::string(bad) +
                                      "' is not a discovery range: LOCALHOST, SUBNET, OFF or SYSTEM_DEFAULT");
  }
}

TEST(RosEnv, StaticPeers) {
  RosEnvironment env;
  // LOCALHOST with peers on this host: still the loopback interface, peers after 127.0.0.1.
  env.ros_static_peers = "127.0.0.2;;localhost ; ";
  DdsSettings s = resolve_ok(env);
  EXPECT_EQ(s.static_peers, (std::vector<std::string>{"127.0.0.2", "localhost"}));
  ASSERT_TRUE(s.config);
  EXPECT_TRUE(has(*s.config, R"(<NetworkInterface address="127.0.0.1"/>)")) << *s.config;
  EXPECT_TRUE(has(*s.config, "<AllowMulticast>false</AllowMulticast>")) << *s.config;
  EXPECT_TRUE(has(
      *s.config,
      R"(<Peers><Peer Address="127.0.0.1"/><Peer Address="127.0.0.2"/><Peer Address="localhost"/></Peers>)"))
      << *s.config;
  EXPECT_EQ(s.describe(), "domain 0 (LOCALHOST, static peers 127.0.0.2;localhost)");

  // A peer on another host: Cyclone's interface (the loopback one cannot reach it), still no multicast.
  env.ros_static_peers = "192.168.1.20;robot.local";
  s = resolve_ok(env);
  EXPECT_FALSE(has(*s.config, "NetworkInterface")) << *s.config;
  EXPECT_TRUE(has(*s.config, "<AllowMulticast>false</AllowMulticast>")) << *s.config;
  EXPECT_TRUE(has(
      *s.config,
      R"(<Peers><Peer Address="127.0.0.1"/><Peer Address="192.168.1.20"/><Peer Address="robot.local"/></Peers>)"))
      << *s.config;

  // SUBNET: the peers alone, multicast as Cyclone's default.
  env.ros_automatic_discovery_range = "SUBNET";
  s = resolve_ok(env);
  EXPECT_TRUE(has(*s.config, R"(<Peers><Peer Address="192.168.1.20"/><Peer Address="robot.local"/></Peers>)"))
      << *s.config;
  EXPECT_TRUE(s.warnings.empty());

  // OFF and SYSTEM_DEFAULT ignore them, with a warning (rcl, rmw_cyclonedds_cpp).
  env.ros_automatic_discovery_range = "OFF";
  s = resolve_ok(env);
  EXPECT_TRUE(s.static_peers.empty());
  EXPECT_FALSE(has(*s.config, "<Peers>"));
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_TRUE(has(s.warnings[0], "ROS_STATIC_PEERS is ignored"));
  env.ros_automatic_discovery_range = "SYSTEM_DEFAULT";
  s = resolve_ok(env);
  EXPECT_FALSE(s.config);
  ASSERT_EQ(s.warnings.size(), 1u);

  // What cannot be a host goes nowhere near the XML.
  for (const char* bad : {"a\"/><Peer Address=\"x", "host name", "a&b", "a,b"}) {
    env.ros_static_peers = bad;
    const std::string e = resolve_error(env);
    EXPECT_TRUE(has(e, "ROS_STATIC_PEERS: '")) << e;
    EXPECT_TRUE(has(e, "is not a host name or IP address")) << e;
  }
  env.ros_static_peers = std::string(300, 'a');
  EXPECT_TRUE(has(resolve_error(env), "longer than 255 characters"));
}

TEST(RosEnv, LegacyLocalhostOnly) {
  RosEnvironment env;
  env.ros_localhost_only = "1";
  DdsSettings s = resolve_ok(env);
  EXPECT_EQ(*s.config, loopback_config());
  EXPECT_TRUE(s.warnings.empty());
  // rcl_init: an enabled ROS_LOCALHOST_ONLY wins over the range and the peers.
  env.ros_automatic_discovery_range = "SUBNET";
  env.ros_static_peers = "192.168.1.20";
  s = resolve_ok(env);
  EXPECT_EQ(s.range, DiscoveryRange::Localhost);
  EXPECT_EQ(*s.config, loopback_config());
  EXPECT_TRUE(s.static_peers.empty());
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_TRUE(has(s.warnings[0], "ROS_LOCALHOST_ONLY=1"));
  // 0: the newer variables decide.
  env.ros_localhost_only = "0";
  s = resolve_ok(env);
  EXPECT_EQ(s.range, DiscoveryRange::Subnet);
  EXPECT_EQ(s.static_peers, std::vector<std::string>{"192.168.1.20"});
  for (const char* bad : {"true", "yes", "2"}) {
    env.ros_localhost_only = bad;
    EXPECT_TRUE(has(resolve_error(env), "ROS_LOCALHOST_ONLY='" + std::string(bad) + "' is neither 1 nor 0"));
  }
}

TEST(RosEnv, CycloneddsUriWinsButRosDomainIdStillChoosesTheDomain) {
  RosEnvironment env;
  env.cyclonedds_uri = "file:///etc/cyclone.xml";
  env.ros_domain_id = "9";
  DdsSettings s = resolve_ok(env);
  EXPECT_EQ(s.domain, 9u);
  EXPECT_TRUE(s.from_cyclonedds_uri);
  EXPECT_FALSE(s.config.has_value());
  EXPECT_TRUE(s.warnings.empty());
  EXPECT_EQ(s.describe(), "domain 9 (CYCLONEDDS_URI)");
  env.ros_automatic_discovery_range = "SUBNET";
  s = resolve_ok(env);
  EXPECT_FALSE(s.config.has_value());
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_TRUE(has(s.warnings[0], "CYCLONEDDS_URI is set"));
  // Values are checked all the same.
  env.ros_automatic_discovery_range = "EVERYWHERE";
  EXPECT_TRUE(has(resolve_error(env), "ROS_AUTOMATIC_DISCOVERY_RANGE='EVERYWHERE'"));
}

// Cyclone accepts the loopback-only configurations generated here (LOCALHOST with local static
// peers, OFF): a participant starts on each, bound to 127.0.0.1. Domains 140/141 are this
// test's own (test/dds uses 142; e2e 200..232).
TEST(RosEnv, CycloneAcceptsTheLoopbackConfigurations) {
  RosEnvironment env;
  env.ros_static_peers = "127.0.0.1;localhost";
  DdsSettings local = resolve_ok(env, 140);
  env.ros_static_peers.reset();
  env.ros_automatic_discovery_range = "OFF";
  DdsSettings off = resolve_ok(env, 141);
  for (const DdsSettings* s : {&local, &off}) {
    ASSERT_TRUE(s->config);
    ASSERT_TRUE(has(*s->config, R"(<NetworkInterface address="127.0.0.1"/>)"));
    const dds_entity_t d = dds_create_domain(s->domain, s->config->c_str());
    ASSERT_GT(d, 0) << dds_strretcode(d) << " for " << *s->config;
    const dds_entity_t p = dds_create_participant(s->domain, nullptr, nullptr);
    EXPECT_GT(p, 0) << dds_strretcode(p);
    if (p > 0) dds_delete(p);
    dds_delete(d);
  }
}

// ROS_DISTRO: the graph's wire format.
RosEnvironment with_distro(std::optional<std::string> distro) {
  RosEnvironment env;
  env.ros_distro = std::move(distro);
  return env;
}

TEST(RosDistro, UnsetOrEmptyIsJazzyWithoutWarning) {
  for (const auto& v : {std::optional<std::string>{}, std::optional<std::string>{""}}) {
    const DistroChoice c = resolve_ros_distro(with_distro(v));
    EXPECT_EQ(c.distro, RosDistro::Jazzy);
    EXPECT_FALSE(c.warning.has_value());
  }
}

TEST(RosDistro, HumbleAndOlderUse24ByteGidsAndNoTypeHashes) {
  for (const char* v : {"humble", "galactic", "foxy"}) {
    const DistroChoice c = resolve_ros_distro(with_distro(v));
    EXPECT_EQ(c.distro, RosDistro::Humble) << v;
    EXPECT_FALSE(c.warning.has_value()) << v;
  }
  EXPECT_EQ(gid_size(RosDistro::Humble), 24u);
  EXPECT_FALSE(has_type_hashes(RosDistro::Humble));
}

TEST(RosDistro, IronAndLaterUse16ByteGidsAndTypeHashes) {
  for (const char* v : {"iron", "jazzy", "kilted", "rolling"}) {
    const DistroChoice c = resolve_ros_distro(with_distro(v));
    EXPECT_EQ(c.distro, RosDistro::Jazzy) << v;
    EXPECT_FALSE(c.warning.has_value()) << v;
  }
  EXPECT_EQ(gid_size(RosDistro::Jazzy), 16u);
  EXPECT_TRUE(has_type_hashes(RosDistro::Jazzy));
}

TEST(RosDistro, UnknownIsOneWarningAndJazzy) {
  const DistroChoice c = resolve_ros_distro(with_distro("Humble"));  // names are lower case
  EXPECT_EQ(c.distro, RosDistro::Jazzy);
  ASSERT_TRUE(c.warning.has_value());
  EXPECT_TRUE(has(*c.warning, "ROS_DISTRO='Humble'")) << *c.warning;
  const DdsSettings s = resolve_ok(with_distro("Humble"));
  EXPECT_EQ(s.distro, RosDistro::Jazzy);
  EXPECT_EQ(s.warnings.size(), 1u);
  EXPECT_EQ(resolve_ok(with_distro("humble")).distro, RosDistro::Humble);
}

TEST(NodeName, LastTokenIsTheNameTheRestTheNamespace) {
  auto n = parse_node_name("a/b/sim");
  ASSERT_TRUE(n.ok()) << n.error().message;
  EXPECT_EQ(n.value().ns, "/a/b");
  EXPECT_EQ(n.value().name, "sim");
  EXPECT_EQ(n.value().fully_qualified(), "/a/b/sim");
  EXPECT_EQ(n.value().logger_name(), "a.b.sim");
  n = parse_node_name("/rbsim");
  ASSERT_TRUE(n.ok()) << n.error().message;
  EXPECT_EQ(n.value().ns, "/");
  EXPECT_EQ(n.value().name, "rbsim");
  EXPECT_EQ(n.value().fully_qualified(), "/rbsim");
  EXPECT_EQ(n.value().logger_name(), "rbsim");
}

TEST(NodeName, RejectsWhatIsNoRosName) {
  for (const char* bad : {"", "/", "a//b", "a/b/", "1a", "a/2b", "a-b", "a b", "a/b.c"}) {
    auto n = parse_node_name(bad);
    EXPECT_FALSE(n.ok()) << bad;
    if (!n.ok()) {
      EXPECT_TRUE(has(n.error().message, "is not a ROS 2 node name")) << n.error().message;
    }
  }
  EXPECT_FALSE(parse_node_name(std::string(256, 'a')).ok());
  EXPECT_TRUE(parse_node_name(std::string(255, 'a')).ok());
}

}  // namespace
}  // namespace rbsim::node
