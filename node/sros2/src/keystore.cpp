// An SROS2 keystore and its enclaves (rbsim/sros2.hpp), laid out as `ros2 security` lays them
// out (sros2/keystore: _keystore.py, _enclave.py; policy templates governance.xml, permissions.xsl).
#include <algorithm>
#include <filesystem>
#include <sstream>

#include "rbsim/atomic_file.hpp"
#include "rbsim/msgs.hpp"
#include "rbsim/openssl_util.hpp"
#include "rbsim/sros2.hpp"

namespace rbsim::node {

namespace fs = std::filesystem;

namespace {

constexpr const char* kCommonName = "sros2CA";  // sros2's keystore CA

// Discovery, liveliness and every topic authenticated, access-controlled and encrypted; no
// unauthenticated participant (sros2's default governance), for the domains security allows.
std::string governance_xml() {
  return R"(<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"
    xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_governance.xsd">
  <domain_access_rules>
    <domain_rule>
      <domains>
        <id_range><min>0</min><max>)" +
         std::to_string(kMaxSecureDomainId) + R"(</max></id_range>
      </domains>
      <allow_unauthenticated_participants>false</allow_unauthenticated_participants>
      <enable_join_access_control>true</enable_join_access_control>
      <discovery_protection_kind>ENCRYPT</discovery_protection_kind>
      <liveliness_protection_kind>ENCRYPT</liveliness_protection_kind>
      <rtps_protection_kind>SIGN</rtps_protection_kind>
      <topic_access_rules>
        <topic_rule>
          <topic_expression>*</topic_expression>
          <enable_discovery_protection>true</enable_discovery_protection>
          <enable_liveliness_protection>true</enable_liveliness_protection>
          <enable_read_access_control>true</enable_read_access_control>
          <enable_write_access_control>true</enable_write_access_control>
          <metadata_protection_kind>ENCRYPT</metadata_protection_kind>
          <data_protection_kind>ENCRYPT</data_protection_kind>
        </topic_rule>
      </topic_access_rules>
    </domain_rule>
  </domain_access_rules>
</dds>
)";
}

std::string iso_date(int years_from_now) {
  const std::time_t now = std::time(nullptr) + static_cast<std::time_t>(years_from_now) * 365 * 24 * 3600;
  std::tm tm{};
  gmtime_r(&now, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT00:00:00", &tm);
  return buf;
}

// The DDS topic names an enclave may use (rmw_cyclonedds_cpp's prefixes: rt/ topics, rq/ and rr/
// service requests and replies). --topics names rbsim topics as every other command does
// (msgs::select_topics: "body_states", "/rbsim/body_states", "tf" for the root /tf); an unknown one
// is an error, not a permission for a topic that does not exist.
Result<std::vector<std::string>> allowed_topics(const EnclaveOptions& o) {
  std::string ns = o.ns;
  while (!ns.empty() && ns.front() == '/') ns.erase(0, 1);
  std::vector<std::string> t;
  if (o.topics.empty()) {
    t.push_back("rt/" + ns + "/*");
  } else {
    const std::vector<msgs::TopicCandidate> candidates = msgs::topic_candidates(ns, /*events=*/true);
    msgs::TopicFilter filter;
    filter.topics = o.topics;
    Result<std::vector<std::size_t>> chosen = msgs::select_topics(filter, candidates);
    if (!chosen) return with_context("--topics: ", chosen.error());
    for (const std::size_t i : chosen.value()) t.push_back(msgs::dds_topic_name(candidates[i].name));
  }
  for (const char* root : {"rt/clock", "rt/tf", "rt/rosout", "rt/parameter_events", "ros_discovery_info"})
    if (std::find(t.begin(), t.end(), root) == t.end()) t.emplace_back(root);
  t.push_back("rq/" + ns + "/*");
  t.push_back("rr/" + ns + "/*");
  t.push_back("rq/rbsim_recorder/*");
  t.push_back("rr/rbsim_recorder/*");
  t.push_back("rq/rbsim_player/*");
  t.push_back("rr/rbsim_player/*");
  return t;
}

std::string permissions_xml(const std::string& enclave, const std::vector<std::string>& allowed) {
  std::ostringstream topics;
  for (const std::string& t : allowed) topics << "              <topic>" << t << "</topic>\n";
  std::ostringstream x;
  x << R"(<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"
    xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_permissions.xsd">
  <permissions>
    <grant name=")"
    << enclave << R"(">
      <subject_name>CN=)"
    << enclave << R"(</subject_name>
      <validity>
        <not_before>)"
    << iso_date(0) << "</not_before>\n        <not_after>" << iso_date(10) << R"(</not_after>
      </validity>
      <allow_rule>
        <domains>
          <id_range><min>0</min><max>)"
    << kMaxSecureDomainId << R"(</max></id_range>
        </domains>
        <publish>
          <topics>
)" << topics.str()
    << R"(          </topics>
        </publish>
        <subscribe>
          <topics>
)" << topics.str()
    << R"(          </topics>
        </subscribe>
      </allow_rule>
      <default>DENY</default>
    </grant>
  </permissions>
</dds>
)";
  return x.str();
}

// Every file of a keystore is written whole and moved into place (AtomicFile): a killed `rbsim
// security` leaves no half-written key, certificate or signed document. A private key is its
// owner's alone (0600) before its first byte is written.
enum class Access { Shared, OwnerOnly };

Status write_file(const fs::path& path, const std::string& text, Access access = Access::Shared) {
  AtomicFile file;
  if (Status st = file.open(path.string(), access == Access::OwnerOnly ? 0600 : 0666); !st) return st;
  if (Status st = file.write(text.data(), text.size()); !st) return st;
  return file.commit();
}

Status write_file(const fs::path& path, const Result<std::string>& text, Access access = Access::Shared) {
  if (!text) return text.error();
  return write_file(path, text.value(), access);
}

Status make_dirs(const fs::path& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) return Error{dir.string() + ": cannot be created (" + ec.message() + ")"};
  return Ok{};
}

// A relative symbolic link, as sros2's create_symlink (replacing one that is there).
Status link(const fs::path& target, const fs::path& at) {
  std::error_code ec;
  fs::remove(at, ec);
  fs::create_symlink(fs::relative(target, at.parent_path()), at, ec);
  if (ec) return Error{at.string() + ": cannot be linked to " + target.string() + " (" + ec.message() + ")"};
  return Ok{};
}

struct Ca {
  ssl::X509Ptr cert;
  ssl::KeyPtr key;
};

Result<Ca> read_ca(const fs::path& keystore) {
  Result<ssl::X509Ptr> cert = ssl::read_certificate((keystore / "public/ca.cert.pem").string());
  if (!cert)
    return Error{cert.error().message + " (not a keystore? rbsim security create-keystore makes one)"};
  Result<ssl::KeyPtr> key = ssl::read_private_key((keystore / "private/ca.key.pem").string());
  if (!key) return key.error();
  return Ca{std::move(cert.value()), std::move(key.value())};
}

}  // namespace

Status create_keystore(const std::string& dir) {
  const fs::path root(dir);
  std::error_code ec;
  if (fs::exists(root / "public/ca.cert.pem", ec))
    return Error{dir + ": already a keystore (public/ca.cert.pem exists); nothing was changed"};
  for (const char* sub : {"public", "private", "enclaves"}) {
    if (Status st = make_dirs(root / sub); !st) return st;
  }
  Result<ssl::KeyPtr> key = ssl::generate_key();
  if (!key) return key.error();
  Result<ssl::X509Ptr> cert = ssl::make_certificate(kCommonName, *key.value(), nullptr, *key.value());
  if (!cert) return cert.error();
  const fs::path ca_key = root / "private/ca.key.pem", ca_cert = root / "public/ca.cert.pem";
  if (Status st = write_file(ca_key, ssl::private_key_pem(*key.value(), ca_key.string()), Access::OwnerOnly);
      !st)
    return st;
  if (Status st = write_file(ca_cert, ssl::certificate_pem(*cert.value(), ca_cert.string())); !st) return st;
  for (const char* role : {"identity_ca", "permissions_ca"}) {
    if (Status st = link(root / "public/ca.cert.pem", root / "public" / (std::string(role) + ".cert.pem"));
        !st)
      return st;
    if (Status st = link(root / "private/ca.key.pem", root / "private" / (std::string(role) + ".key.pem"));
        !st)
      return st;
  }
  const std::string governance = governance_xml();
  if (Status st = write_file(root / "enclaves/governance.xml", governance); !st) return st;
  const fs::path signed_governance = root / "enclaves/governance.p7s";
  return write_file(signed_governance,
                    ssl::smime(governance, *cert.value(), *key.value(), signed_governance.string()));
}

Status create_enclave(const std::string& keystore, const std::string& enclave,
                      const EnclaveOptions& options) {
  if (enclave.size() < 2 || enclave[0] != '/' || enclave.back() == '/' ||
      enclave.find("//") != std::string::npos || enclave.find("..") != std::string::npos) {
    return Error{"enclave \"" + enclave + "\": an absolute path of names (\"/rbsim\", \"/robots/arm\")",
                 ErrorCode::InvalidArgument};
  }
  if (const std::string problem = msgs::ros_namespace_problem(options.ns); !problem.empty())
    return Error{"--namespace \"" + options.ns + "\" is not a ROS 2 namespace: it " + problem,
                 ErrorCode::InvalidArgument};
  Result<std::vector<std::string>> allowed = allowed_topics(options);  // before any file is made
  if (!allowed) return allowed.error();
  const fs::path root(keystore);
  Result<Ca> ca = read_ca(root);
  if (!ca) return ca.error();
  const fs::path dir = root / "enclaves" / enclave.substr(1);
  if (Status st = make_dirs(dir); !st) return st;
  if (Status st = link(root / "public/identity_ca.cert.pem", dir / "identity_ca.cert.pem"); !st) return st;
  if (Status st = link(root / "public/permissions_ca.cert.pem", dir / "permissions_ca.cert.pem"); !st)
    return st;
  if (Status st = link(root / "enclaves/governance.p7s", dir / "governance.p7s"); !st) return st;
  Result<ssl::KeyPtr> key = ssl::generate_key();
  if (!key) return key.error();
  Result<ssl::X509Ptr> cert = ssl::make_certificate(enclave, *key.value(), ca->cert.get(), *ca->key);
  if (!cert) return cert.error();
  if (Status st = write_file(dir / "key.pem", ssl::private_key_pem(*key.value(), (dir / "key.pem").string()),
                             Access::OwnerOnly);
      !st)
    return st;
  if (Status st =
          write_file(dir / "cert.pem", ssl::certificate_pem(*cert.value(), (dir / "cert.pem").string()));
      !st)
    return st;
  const std::string permissions = permissions_xml(enclave, allowed.value());
  if (Status st = write_file(dir / "permissions.xml", permissions); !st) return st;
  const fs::path signed_permissions = dir / "permissions.p7s";
  return write_file(signed_permissions,
                    ssl::smime(permissions, *ca->cert, *ca->key, signed_permissions.string()));
}

}  // namespace rbsim::node
