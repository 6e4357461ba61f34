// SROS2 keystores and enclaves, made as `ros2 security create-keystore` / `create-enclave` make
// theirs (sros2: one EC P-256 CA for identities and permissions, S/MIME-signed governance and
// permissions), with OpenSSL (rbsim/openssl_util.hpp). No DDS: node/dds's security configuration
// (rbsim/security.hpp) points Cyclone's plugins at an enclave's files.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "rbsim/status.hpp"

namespace rbsim::node {

// Cyclone DDS 0.10's security plugins refuse domain ids above this.
inline constexpr std::uint32_t kMaxSecureDomainId = 230;

// The files of an enclave directory (keystore/enclaves/<enclave>/), in the order they are checked.
inline constexpr const char* kEnclaveFiles[] = {
    "identity_ca.cert.pem",    "cert.pem",       "key.pem",
    "permissions_ca.cert.pem", "governance.p7s", "permissions.p7s"};

// `rbsim security create-keystore DIR`: DIR/public/{ca,identity_ca,permissions_ca}.cert.pem,
// DIR/private/ca.key.pem (and its two names), DIR/enclaves/governance.{xml,p7s}: discovery,
// liveliness and every topic protected and encrypted, no unauthenticated participants.
[[nodiscard]] Status create_keystore(const std::string& dir);

struct EnclaveOptions {
  std::string ns = "rbsim";  // the namespace whose topics and services the enclave may use
  // rbsim topics the enclave may publish and subscribe to, named as every command names them
  // (msgs::select_topics: "body_states", "/rbsim/body_states"; an unknown one is an error); empty:
  // all (rt/<ns>/*). Services of <ns>, /clock, /tf, /rosout, /parameter_events and
  // ros_discovery_info are always allowed.
  std::vector<std::string> topics{};
};
// `rbsim security create-enclave DIR ENCLAVE`: DIR/enclaves/<ENCLAVE>/ with its key and
// certificate (subject CN=<ENCLAVE>, signed by the keystore's CA), the CA certificates and the
// governance (as links, as sros2 makes them), and permissions.{xml,p7s} for the domains 0..230.
[[nodiscard]] Status create_enclave(const std::string& keystore, const std::string& enclave,
                                    const EnclaveOptions& options = {});

}  // namespace rbsim::node
