// DDS Security settings and keystores (rbsim/security.hpp): ROS_SECURITY_* as rcl reads them, the
// enclave files checked before Cyclone sees them, keystores and enclaves as sros2 lays them out,
// and a secured participant that Cyclone's plugins accept.
#include "rbsim/security.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "rbsim/dds.hpp"
#include "rbsim/subprocess.hpp"

namespace rbsim::node {
namespace {

namespace fs = std::filesystem;

RosEnvironment secured(const fs::path& keystore, const char* strategy = "Enforce") {
  RosEnvironment env;
  env.ros_security_enable = "true";
  env.ros_security_strategy = strategy;
  env.ros_security_keystore = keystore.string();
  return env;
}

const NodeName kNode{"/", "sec_node"};

// One keystore for the file: making keys costs little, but every test reads the same layout.
class Security : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new test::TempDir();
    ASSERT_TRUE(create_keystore((ks() / "").string()));
    ASSERT_TRUE(create_enclave(ks().string(), "/sec_node", {.ns = "sec_node"}));
    ASSERT_TRUE(create_keystore((other() / "").string()));
    ASSERT_TRUE(create_enclave(other().string(), "/sec_node", {.ns = "sec_node"}));
  }
  static void TearDownTestSuite() { delete dir_; }
  static fs::path ks() { return dir_->path() / "keystore"; }
  static fs::path other() { return dir_->path() / "other"; }
  static fs::path copy_enclave(const std::string& name) {
    const fs::path to = dir_->path() / name / "enclaves/sec_node";
    fs::create_directories(to);
    for (const char* f : kEnclaveFiles) fs::copy_file(ks() / "enclaves/sec_node" / f, to / f);
    return dir_->path() / name;
  }
  static test::TempDir* dir_;
};
test::TempDir* Security::dir_ = nullptr;

TEST_F(Security, ResolveSecurityIsOffUnlessEnableIsTrue) {
  RosEnvironment env = secured(ks());
  env.ros_security_enable = "1";  // rcl: only "true"
  Result<SecuritySettings> s = resolve_security(env, kNode, 0, "ROS_DOMAIN_ID");
  ASSERT_TRUE(s);
  EXPECT_FALSE(s->requested);
  EXPECT_FALSE(s->enabled);
  EXPECT_EQ(s->describe(), "unsecured");
}

TEST_F(Security, ResolveSecurityUsesTheNodeNameOrTheOverrideAsEnclave) {
  Result<SecuritySettings> s = resolve_security(secured(ks()), kNode, 7, "--domain");
  ASSERT_TRUE(s) << s.error().message;
  EXPECT_TRUE(s->enabled);
  EXPECT_EQ(s->enclave, "/sec_node");
  EXPECT_EQ(s->directory, (ks() / "enclaves/sec_node").string());
  EXPECT_EQ(s->describe(), "secured as enclave /sec_node (Enforce)");
  RosEnvironment env = secured(ks());
  env.ros_security_enclave_override = "/elsewhere";
  Result<SecuritySettings> o = resolve_security(env, kNode, 7, "--domain");
  ASSERT_FALSE(o);
  EXPECT_NE(o.error().message.find((ks() / "enclaves/elsewhere").string() + ": no such enclave directory"),
            std::string::npos)
      << o.error().message;
}

TEST_F(Security, ResolveSecurityRefusesDomainsAbove230NamingTheVariable) {
  Result<SecuritySettings> s = resolve_security(secured(ks()), kNode, 231, "ROS_DOMAIN_ID");
  ASSERT_FALSE(s);
  EXPECT_NE(
      s.error().message.find("ROS_DOMAIN_ID=231: Cyclone DDS 0.10's security supports domain ids 0..230"),
      std::string::npos)
      << s.error().message;
  EXPECT_TRUE(resolve_security(secured(ks()), kNode, 230, "ROS_DOMAIN_ID"));
}

TEST_F(Security, EnforceRefusesAMissingFileNamingItPermissiveWarns) {
  const fs::path ks2 = copy_enclave("missing");
  fs::remove(ks2 / "enclaves/sec_node/key.pem");
  Result<SecuritySettings> e = resolve_security(secured(ks2), kNode, 0, "ROS_DOMAIN_ID");
  ASSERT_FALSE(e);
  EXPECT_EQ(e.error().message,
            (ks2 / "enclaves/sec_node/key.pem").string() + ": missing (an enclave holds it)");
  Result<SecuritySettings> p = resolve_security(secured(ks2, "Permissive"), kNode, 0, "ROS_DOMAIN_ID");
  ASSERT_TRUE(p);
  EXPECT_FALSE(p->enabled);
  ASSERT_EQ(p->warnings.size(), 1u);
  EXPECT_NE(p->warnings[0].find("key.pem: missing"), std::string::npos);
  EXPECT_NE(p->warnings[0].find("running unsecured"), std::string::npos);
  RosEnvironment no_keystore = secured(ks());
  no_keystore.ros_security_keystore.reset();
  Result<SecuritySettings> k = resolve_security(no_keystore, kNode, 0, "ROS_DOMAIN_ID");
  ASSERT_FALSE(k);
  EXPECT_NE(k.error().message.find("ROS_SECURITY_KEYSTORE is not set"), std::string::npos);
}

TEST_F(Security, VerifyEnclaveFindsATamperedPermissionsFile) {
  const fs::path ks2 = copy_enclave("tampered");
  const fs::path p7s = ks2 / "enclaves/sec_node/permissions.p7s";
  std::string text = test::read_text(p7s);
  const std::size_t at = text.find("<default>DENY</default>");
  ASSERT_NE(at, std::string::npos);
  text.replace(at, 23, "<default>ALLOW</default");  // same length: only the signature can tell
  std::ofstream(p7s, std::ios::trunc) << text;
  const Status st = verify_enclave((ks2 / "enclaves/sec_node").string());
  ASSERT_FALSE(st);
  EXPECT_NE(st.error().message.find(p7s.string() + ": its signature does not verify"), std::string::npos)
      << st.error().message;
}

TEST_F(Security, VerifyEnclaveRefusesACertificateOfAnotherCa) {
  const fs::path ks2 = copy_enclave("foreign");
  fs::copy_file(other() / "enclaves/sec_node/cert.pem", ks2 / "enclaves/sec_node/cert.pem",
                fs::copy_options::overwrite_existing);
  const Status st = verify_enclave((ks2 / "enclaves/sec_node").string());
  ASSERT_FALSE(st);
  EXPECT_NE(st.error().message.find("cert.pem: not signed by that CA"), std::string::npos)
      << st.error().message;
}

TEST_F(Security, CreateKeystoreAndEnclaveLayOutSros2sFiles) {
  for (const char* f : {"public/ca.cert.pem", "public/identity_ca.cert.pem", "public/permissions_ca.cert.pem",
                        "private/ca.key.pem", "enclaves/governance.xml", "enclaves/governance.p7s"}) {
    EXPECT_TRUE(fs::exists(ks() / f)) << f;
  }
  for (const char* key : {"private/ca.key.pem", "enclaves/sec_node/key.pem"}) {
    EXPECT_EQ(fs::status(ks() / key).permissions() & fs::perms::all,
              fs::perms::owner_read | fs::perms::owner_write)
        << key;
  }
  for (const fs::directory_entry& e : fs::recursive_directory_iterator(ks())) {
    EXPECT_EQ(e.path().filename().string().find(".tmp."), std::string::npos)
        << "a temporary left: " << e.path();
  }
  EXPECT_TRUE(verify_enclave((ks() / "enclaves/sec_node").string()));
  const std::string permissions = test::read_text(ks() / "enclaves/sec_node/permissions.xml");
  EXPECT_NE(permissions.find("<subject_name>CN=/sec_node</subject_name>"), std::string::npos);
  EXPECT_NE(permissions.find("<topic>rt/sec_node/*</topic>"), std::string::npos);
  const Status again = create_keystore(ks().string());
  ASSERT_FALSE(again);
  EXPECT_NE(again.error().message.find("already a keystore"), std::string::npos);
  const Status bad = create_enclave(ks().string(), "relative/name");
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.code(), ErrorCode::InvalidArgument);
  const Status none = create_enclave((dir_->path() / "nothing").string(), "/x");
  ASSERT_FALSE(none);
  EXPECT_NE(none.error().message.find("not a keystore?"), std::string::npos) << none.error().message;
  ASSERT_TRUE(create_enclave(ks().string(), "/restricted", {.ns = "sec_node", .topics = {"scene"}}));
  const std::string restricted = test::read_text(ks() / "enclaves/restricted/permissions.xml");
  EXPECT_NE(restricted.find("<topic>rt/sec_node/scene</topic>"), std::string::npos);
  EXPECT_EQ(restricted.find("rt/sec_node/*"), std::string::npos);
  // Names as every command takes them: a full name, and /tf (at the root) listed once.
  ASSERT_TRUE(
      create_enclave(ks().string(), "/named", {.ns = "sec_node", .topics = {"/sec_node/energy", "tf"}}));
  const std::string named = test::read_text(ks() / "enclaves/named/permissions.xml");
  EXPECT_NE(named.find("<topic>rt/sec_node/energy</topic>"), std::string::npos) << named;
  // Each allowed topic appears once in the publish rule and once in the subscribe rule.
  const auto count = [&named](const std::string& what) {
    std::size_t n = 0;
    for (auto at = named.find(what); at != std::string::npos; at = named.find(what, at + 1)) ++n;
    return n;
  };
  EXPECT_EQ(count("<topic>rt/tf</topic>"), 2u) << named;
  EXPECT_EQ(count("<topic>rt/sec_node/energy</topic>"), 2u) << named;
  EXPECT_EQ(named.find("rt/sec_node/tf"), std::string::npos) << named;
  // A name that selects no topic is refused before anything is made.
  const Status unknown = create_enclave(ks().string(), "/unknown", {.ns = "sec_node", .topics = {"nope"}});
  ASSERT_FALSE(unknown);
  EXPECT_NE(unknown.error().message.find("--topics: unknown topic \"nope\""), std::string::npos)
      << unknown.error().message;
  EXPECT_FALSE(std::filesystem::exists(ks() / "enclaves/unknown"));
}

// Cyclone's own plugins load the files and create the participant (its handshake is the e2e
// case's: two participants on two hosts).
TEST_F(Security, ParticipantCreateIsSecuredByCyclonesPlugins) {
  ::setenv("ROS_SECURITY_ENABLE", "true", 1);
  ::setenv("ROS_SECURITY_STRATEGY", "Enforce", 1);
  ::setenv("ROS_SECURITY_KEYSTORE", ks().c_str(), 1);
  Result<Participant> p = create_dds_participant(57, kNode);
  ::unsetenv("ROS_SECURITY_ENABLE");
  ASSERT_TRUE(p) << p.error().message;
  EXPECT_NE(p->description().find("secured as enclave /sec_node (Enforce)"), std::string::npos)
      << p->description();
}

}  // namespace
}  // namespace rbsim::node
