// --foxglove [ADDR:]PORT, shared by rbsim node, replay and bridge: the option, and starting the
// server with the lines that tell a person where to point Foxglove.
#include <cstdio>
#include <filesystem>
#include <system_error>

#include "commands.hpp"
#include "rbsim/rosout.hpp"

#ifndef RBSIM_FOXGLOVE_LAYOUT
#define RBSIM_FOXGLOVE_LAYOUT "docs/foxglove-layout.json"
#endif

namespace rbsim::cli {

namespace {

// Where the layout is: installed beside the binary (<prefix>/share/rbsim, cmake --install and the
// Debian package), else in the source tree this binary was built from.
std::string layout_path() {
  std::error_code ec;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const std::filesystem::path installed =
        exe.parent_path().parent_path() / "share/rbsim/foxglove-layout.json";
    if (std::filesystem::exists(installed, ec)) return installed.string();
  }
  return RBSIM_FOXGLOVE_LAYOUT;
}

}  // namespace

CLI::Option* add_foxglove_option(CLI::App* app, std::optional<std::string>& address, bool required) {
  CLI::Option* o = app->add_option(
      "--foxglove", address,
      "Serve the topics to Foxglove over its WebSocket protocol on [ADDR:]PORT (ADDR defaults to 127.0.0.1; "
      "0.0.0.0 serves every interface; port 0 picks a free port); prints the link to open");
  o->type_name("[ADDR:]PORT");
  o->check(CLI::Validator(
      [](std::string& value) -> std::string {
        foxglove::ServerOptions options;
        const Status st = foxglove::parse_listen_address(value, options);
        return st ? std::string() : st.error().message;
      },
      ""));  // the type name already says [ADDR:]PORT
  if (required) o->required();
  return o;
}

Result<std::unique_ptr<foxglove::Server>> start_foxglove(const char* command, const std::string& address,
                                                         std::vector<foxglove::ChannelSpec> channels,
                                                         control::Steering* steering,
                                                         const std::string& node) {
  foxglove::ServerOptions options;
  if (Status st = foxglove::parse_listen_address(address, options); !st) return st.error();
  options.steering = steering;
  options.node = node;
  auto server = foxglove::Server::start(options, std::move(channels));
  if (!server) return server.error();
  const std::uint16_t port = server.value()->port();
  // The line tests and scripts read the port from (port 0 picks one).
  RBSIM_LOG(Info, "%s: foxglove: listening on %s\n", command,
            foxglove::websocket_url(options.address, port).c_str());
  // A browser cannot connect to 0.0.0.0 (or ::): the link names this host's loopback instead.
  std::string host = options.address;
  if (host == "0.0.0.0") host = "127.0.0.1";
  if (host == "::") host = "::1";
  RBSIM_LOG(Info, "%s: foxglove: open %s\n", command,
            foxglove::foxglove_app_link(foxglove::websocket_url(host, port)).c_str());
  RBSIM_LOG(Info, "%s: foxglove: layout %s (Foxglove: Layouts > Import from file)\n", command,
            layout_path().c_str());
  return server;
}

std::string foxglove_summary(const foxglove::Server& server) {
  const foxglove::ServerStats s = server.stats();
  std::string line = "foxglove: " + std::to_string(s.clients) + (s.clients == 1 ? " client" : " clients") +
                     ", " + std::to_string(s.published) + " messages queued, " + std::to_string(s.dropped) +
                     " dropped for slow clients";
  if (s.disconnected > 0) line += ", " + std::to_string(s.disconnected) + " disconnected for not reading";
  if (s.refused > 0) line += ", " + std::to_string(s.refused) + " handshakes refused";
  if (s.requests > 0)
    line += ", " + std::to_string(s.requests) + (s.requests == 1 ? " request" : " requests");
  if (s.refused_requests > 0) line += ", " + std::to_string(s.refused_requests) + " requests refused";
  return line;
}

}  // namespace rbsim::cli
