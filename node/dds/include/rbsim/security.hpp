// DDS Security the ROS 2 way: rcl's ROS_SECURITY_* variables (rcl/src/rcl/security.c) choose an
// enclave of an SROS2 keystore, and its files configure Cyclone DDS's authentication, access
// control and cryptography plugins as rmw_cyclonedds_cpp does (configure_qos_for_security in
// rmw_node.cpp: participant QoS properties dds.sec.*). The keystore is made as `ros2 security
// create-keystore` / `create-enclave` make theirs (sros2: one EC P-256 CA for identities and
// permissions, S/MIME-signed governance and permissions).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "rbsim/ros_env.hpp"
#include "rbsim/status.hpp"

namespace rbsim::node {

// Cyclone DDS 0.10's security plugins refuse domain ids above this.
inline constexpr std::uint32_t kMaxSecureDomainId = 230;

// The files of an enclave directory (keystore/enclaves/<enclave>/), in the order they are checked.
inline constexpr const char* kEnclaveFiles[] = {
    "identity_ca.cert.pem",    "cert.pem",       "key.pem",
    "permissions_ca.cert.pem", "governance.p7s", "permissions.p7s"};

enum class SecurityStrategy { Enforce, Permissive };

struct SecuritySettings {
  bool requested = false;  // ROS_SECURITY_ENABLE=true
  bool enabled = false;    // the participant is created secured
  SecurityStrategy strategy = SecurityStrategy::Permissive;
  std::string enclave;    // "/rbsim" (the node's fully qualified name, or ROS_SECURITY_ENCLAVE_OVERRIDE)
  std::string directory;  // <keystore>/enclaves/rbsim
  std::vector<std::string> warnings;  // Permissive's reasons for running unsecured
  // "secured as enclave /rbsim (Enforce)", or "unsecured".
  std::string describe() const;
};

// ROS_SECURITY_ENABLE=true turns security on (anything else: off); ROS_SECURITY_STRATEGY=Enforce
// makes a missing or invalid file an error (naming it), otherwise (Permissive) a warning and an
// unsecured participant; ROS_SECURITY_KEYSTORE is the keystore, its enclaves/<enclave>/ the files
// (verify_enclave); the enclave is the node's fully qualified name unless
// ROS_SECURITY_ENCLAVE_OVERRIDE names one. `domain_source` names where the domain came from
// ("ROS_DOMAIN_ID", "--domain") for the error a secured domain above 230 gets.
Result<SecuritySettings> resolve_security(const RosEnvironment& env, const NodeName& node,
                                          std::uint32_t domain, const std::string& domain_source);

// Every file of an enclave directory present and valid: the certificates parse, cert.pem is
// signed by identity_ca.cert.pem and matches key.pem, governance.p7s and permissions.p7s are
// S/MIME documents signed by permissions_ca.cert.pem. The error names the file and what is wrong.
[[nodiscard]] Status verify_enclave(const std::string& directory);

// The participant QoS properties of a secured participant (dds_qos_t*, as void* to keep DDS out
// of this header).
void set_security_properties(void* qos, const SecuritySettings& settings);

// `rbsim security create-keystore DIR`: DIR/public/{ca,identity_ca,permissions_ca}.cert.pem,
// DIR/private/ca.key.pem (and its two names), DIR/enclaves/governance.{xml,p7s}: discovery,
// liveliness and every topic protected and encrypted, no unauthenticated participants.
[[nodiscard]] Status create_keystore(const std::string& dir);

struct EnclaveOptions {
  std::string ns = "rbsim";  // the namespace whose topics and services the enclave may use
  // rbsim topics (suffixes, "body_states") the enclave may publish and subscribe to; empty: all
  // (rt/<ns>/*). Services of <ns>, /clock, /tf, /rosout, /parameter_events and
  // ros_discovery_info are always allowed.
  std::vector<std::string> topics{};
};
// `rbsim security create-enclave DIR ENCLAVE`: DIR/enclaves/<ENCLAVE>/ with its key and
// certificate (subject CN=<ENCLAVE>, signed by the keystore's CA), the CA certificates and the
// governance (as links, as sros2 makes them), and permissions.{xml,p7s} for the domains 0..230.
[[nodiscard]] Status create_enclave(const std::string& keystore, const std::string& enclave,
                                    const EnclaveOptions& options = {});

}  // namespace rbsim::node
