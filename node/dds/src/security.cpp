// ROS_SECURITY_* -> a secured participant (rbsim/security.hpp): the enclave chosen as rcl chooses
// it, its files checked with OpenSSL before Cyclone sees them (so an error names the file), and
// the participant properties rmw_cyclonedds_cpp sets.
#include "rbsim/security.hpp"

#include <dds/dds.h>
#include <openssl/bio.h>
#include <openssl/pem.h>
#include <openssl/pkcs7.h>
#include <openssl/x509.h>

#include <filesystem>
#include <memory>

#include "rbsim/openssl_util.hpp"

namespace rbsim::node {

namespace fs = std::filesystem;

std::string SecuritySettings::describe() const {
  if (!enabled) return "unsecured";
  return "secured as enclave " + enclave + " (" +
         (strategy == SecurityStrategy::Enforce ? "Enforce" : "Permissive") + ")";
}

namespace {

bool set(const std::optional<std::string>& v) {
  return v && !v->empty();
}

}  // namespace

Result<SecuritySettings> resolve_security(const RosEnvironment& env, const NodeName& node,
                                          std::uint32_t domain, const std::string& domain_source) {
  SecuritySettings s;
  if (!set(env.ros_security_enable) || *env.ros_security_enable != "true") return s;
  s.requested = true;
  s.strategy = set(env.ros_security_strategy) && *env.ros_security_strategy == "Enforce"
                   ? SecurityStrategy::Enforce
                   : SecurityStrategy::Permissive;
  s.enclave =
      set(env.ros_security_enclave_override) ? *env.ros_security_enclave_override : node.fully_qualified();
  const auto refuse = [&s](const std::string& why) -> Result<SecuritySettings> {
    if (s.strategy == SecurityStrategy::Enforce) return Error{why};
    s.warnings.push_back(why + "; running unsecured (ROS_SECURITY_STRATEGY is not Enforce)");
    return s;
  };
  if (s.enclave.empty() || s.enclave[0] != '/') {
    return refuse("ROS_SECURITY_ENCLAVE_OVERRIDE=" + s.enclave +
                  ": an enclave is an absolute path (\"/rbsim\")");
  }
  if (!set(env.ros_security_keystore))
    return refuse("ROS_SECURITY_ENABLE=true but ROS_SECURITY_KEYSTORE is not set");
  s.directory =
      (fs::path(*env.ros_security_keystore) / "enclaves" / s.enclave.substr(1)).lexically_normal().string();
  if (domain > kMaxSecureDomainId) {
    return Error{domain_source + "=" + std::to_string(domain) +
                 ": Cyclone DDS 0.10's security supports domain ids 0.." +
                 std::to_string(kMaxSecureDomainId) + " only (ROS_SECURITY_ENABLE=true)"};
  }
  if (Status st = verify_enclave(s.directory); !st) return refuse(st.error().message);
  s.enabled = true;
  return s;
}

Status verify_enclave(const std::string& directory) {
  const auto file = [&directory](const char* name) { return (fs::path(directory) / name).string(); };
  std::error_code ec;
  if (!fs::is_directory(directory, ec)) {
    return Error{directory + ": no such enclave directory (rbsim security create-enclave makes one)"};
  }
  for (const char* name : kEnclaveFiles) {
    if (!fs::is_regular_file(file(name), ec)) return Error{file(name) + ": missing (an enclave holds it)"};
  }
  Result<ssl::X509Ptr> identity_ca = ssl::read_certificate(file("identity_ca.cert.pem"));
  if (!identity_ca) return identity_ca.error();
  Result<ssl::X509Ptr> cert = ssl::read_certificate(file("cert.pem"));
  if (!cert) return cert.error();
  Result<ssl::KeyPtr> key = ssl::read_private_key(file("key.pem"));
  if (!key) return key.error();
  Result<ssl::X509Ptr> permissions_ca = ssl::read_certificate(file("permissions_ca.cert.pem"));
  if (!permissions_ca) return permissions_ca.error();
  if (Status st = ssl::verify_issued_by(*cert.value(), *identity_ca.value()); !st)
    return Error{file("cert.pem") + ": " + st.error().message + " (by " + file("identity_ca.cert.pem") + ")"};
  if (X509_check_private_key(cert.value().get(), key.value().get()) != 1)
    return Error{file("key.pem") + ": not the key of " + file("cert.pem")};
  for (const char* signed_file : {"governance.p7s", "permissions.p7s"}) {
    if (Status st = ssl::verify_smime(file(signed_file), *permissions_ca.value()); !st) {
      return Error{file(signed_file) + ": " + st.error().message + " (by " + file("permissions_ca.cert.pem") +
                   ")"};
    }
  }
  return Ok{};
}

void set_security_properties(void* qos_ptr, const SecuritySettings& s) {
  auto* qos = static_cast<dds_qos_t*>(qos_ptr);
  const auto uri = [&s](const char* name) { return "file:" + (fs::path(s.directory) / name).string(); };
  dds_qset_prop(qos, "dds.sec.auth.identity_ca", uri("identity_ca.cert.pem").c_str());
  dds_qset_prop(qos, "dds.sec.auth.identity_certificate", uri("cert.pem").c_str());
  dds_qset_prop(qos, "dds.sec.auth.private_key", uri("key.pem").c_str());
  dds_qset_prop(qos, "dds.sec.access.permissions_ca", uri("permissions_ca.cert.pem").c_str());
  dds_qset_prop(qos, "dds.sec.access.governance", uri("governance.p7s").c_str());
  dds_qset_prop(qos, "dds.sec.access.permissions", uri("permissions.p7s").c_str());
  // Debian ships the plugins beside libddsc, outside the loader's search path: by full path.
  const std::string dir = RBSIM_DDS_SECURITY_DIR;
  dds_qset_prop(qos, "dds.sec.auth.library.path", (dir + "/libdds_security_auth.so").c_str());
  dds_qset_prop(qos, "dds.sec.auth.library.init", "init_authentication");
  dds_qset_prop(qos, "dds.sec.auth.library.finalize", "finalize_authentication");
  dds_qset_prop(qos, "dds.sec.crypto.library.path", (dir + "/libdds_security_crypto.so").c_str());
  dds_qset_prop(qos, "dds.sec.crypto.library.init", "init_crypto");
  dds_qset_prop(qos, "dds.sec.crypto.library.finalize", "finalize_crypto");
  dds_qset_prop(qos, "dds.sec.access.library.path", (dir + "/libdds_security_ac.so").c_str());
  dds_qset_prop(qos, "dds.sec.access.library.init", "init_access_control");
  dds_qset_prop(qos, "dds.sec.access.library.finalize", "finalize_access_control");
}

}  // namespace rbsim::node
