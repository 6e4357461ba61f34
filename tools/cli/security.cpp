// rbsim security: an SROS2 keystore and its enclaves, as `ros2 security create-keystore` and
// `create-enclave` make them (rbsim/security.hpp), for ROS_SECURITY_KEYSTORE.
#include <memory>

#include "cli_util.hpp"
#include "commands.hpp"
#include "rbsim/security.hpp"

namespace rbsim::cli {

namespace {
struct SecurityArgs {
  std::string keystore, enclave;
  node::EnclaveOptions enclave_options;
  CLI::App* keystore_app = nullptr;
  CLI::App* enclave_app = nullptr;
};

int security_command(const SecurityArgs& a) {
  if (a.keystore_app->parsed()) {
    if (Status st = node::create_keystore(a.keystore); !st) return fail("security", st.error().message);
    std::printf(
        "rbsim security: keystore %s: CA public/ca.cert.pem (identity and permissions), "
        "enclaves/governance.p7s\n",
        a.keystore.c_str());
    return 0;
  }
  if (Status st = node::create_enclave(a.keystore, a.enclave, a.enclave_options); !st)
    return fail("security", st.error().message, st.code() == ErrorCode::InvalidArgument ? 2 : 1);
  std::printf("rbsim security: enclave %s in %s/enclaves%s\n", a.enclave.c_str(), a.keystore.c_str(),
              a.enclave.c_str());
  return 0;
}
}  // namespace

Subcommand add_security_command(CLI::App& parent) {
  auto a = std::make_shared<SecurityArgs>();
  CLI::App* app = parent.add_subcommand(
      "security", "Make an SROS2 keystore and enclaves for DDS Security (ROS_SECURITY_ENABLE=true)");
  app->require_subcommand(1);
  a->keystore_app = app->add_subcommand("create-keystore", "Make a keystore: a CA and the signed governance");
  a->keystore_app->add_option("dir", a->keystore, "Keystore folder (made if missing)")->required();
  a->enclave_app = app->add_subcommand(
      "create-enclave",
      "Make an enclave: its key and certificate, signed by the keystore's CA, and its permissions");
  a->enclave_app->add_option("dir", a->keystore, "Keystore folder (rbsim security create-keystore)")
      ->required();
  a->enclave_app->add_option("enclave", a->enclave, "Enclave path: a node's fully qualified name (/rbsim)")
      ->required();
  a->enclave_app
      ->add_option("--namespace", a->enclave_options.ns,
                   "Namespace whose topics and services the enclave may use")
      ->default_str("rbsim");
  a->enclave_app
      ->add_option("--topics", a->enclave_options.topics,
                   "Only these rbsim topics of the namespace (comma-separated, named as --topics "
                   "of every command: scene,body_states or /rbsim/body_states); default: all of them")
      ->delimiter(',');
  app->footer(
      "A process uses enclave <keystore>/enclaves/<node name> (ROS_SECURITY_ENCLAVE_OVERRIDE names another) "
      "when ROS_SECURITY_ENABLE=true and ROS_SECURITY_KEYSTORE=<keystore>; ROS_SECURITY_STRATEGY=Enforce "
      "refuses to start without valid files, Permissive runs unsecured with a warning. The governance "
      "encrypts discovery, liveliness and every topic, and admits no unauthenticated participant; domain ids "
      "0..230 (Cyclone DDS 0.10's limit). The permissions allow the namespace's topics and services, "
      "/clock, /tf, /rosout, /parameter_events, ros_discovery_info and the recorder's and player's "
      "services.\nExit status: 0 done, 1 error (an existing keystore, unwritable folder), 2 usage error.");
  return {app, [a] { return security_command(*a); }};
}

}  // namespace rbsim::cli
