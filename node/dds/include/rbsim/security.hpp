// DDS Security the ROS 2 way: rcl's ROS_SECURITY_* variables (rcl/src/rcl/security.c) choose an
// enclave of an SROS2 keystore, and its files configure Cyclone DDS's authentication, access
// control and cryptography plugins as rmw_cyclonedds_cpp does (configure_qos_for_security in
// rmw_node.cpp: participant QoS properties dds.sec.*). The keystore is made as `ros2 security
// create-keystore` / `create-enclave` make theirs (sros2: one EC P-256 CA for identities and
// permissions, S/MIME-signed governance and permissions; node/sros2, rbsim/sros2.hpp).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "rbsim/ros_env.hpp"
#include "rbsim/sros2.hpp"
#include "rbsim/status.hpp"

namespace rbsim::node {

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

}  // namespace rbsim::node
