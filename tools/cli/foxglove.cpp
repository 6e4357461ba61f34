// --foxglove [ADDR:]PORT, shared by rbsim node, replay and bridge: the option and its access options
// (token, --foxglove-insecure, client limit), and starting the server with the lines that tell a
// person where to point Foxglove.
#include <cstdio>
#include <cstdlib>

#include "cli_util.hpp"
#include "commands.hpp"
#include "rbsim/counts.hpp"
#include "rbsim/print.hpp"

namespace rbsim::cli {

CLI::Option* add_foxglove_option(CLI::App* app, FoxgloveArgs& args, bool required) {
  CLI::Option* o = app->add_option(
      "--foxglove", args.address,
      "Serve the topics to Foxglove over its WebSocket protocol on [ADDR:]PORT (ADDR defaults to 127.0.0.1; "
      "0.0.0.0 serves every interface, which needs --foxglove-token-file or --foxglove-insecure; port 0 "
      "picks a free port); prints the link to open");
  o->type_name("[ADDR:]PORT");
  o->check(CLI::Validator(
      [](std::string& value) -> std::string {
        foxglove::ServerOptions options;
        const Status st = foxglove::parse_listen_address(value, options);
        return st ? std::string() : st.error().message;
      },
      ""));  // the type name already says [ADDR:]PORT
  if (required) o->required();
  app->add_option(
         "--foxglove-token-file", args.token_file,
         "Foxglove clients must present the token in FILE (?token=... in the URL or an Authorization: "
         "Bearer header; else HTTP 401): at least 16 printable characters, the file private to its "
         "owner (chmod 600); default: the environment variable RBSIM_FOXGLOVE_TOKEN")
      ->type_name("FILE");
  app->add_flag("--foxglove-insecure", args.insecure,
                "Serve --foxglove on an address other hosts reach without a token (anyone who reaches it may "
                "watch and steer)");
  app->add_flag("--print-token", args.print_token, "Print the --foxglove links with the token in them");
  app->add_option("--foxglove-max-clients", args.max_clients,
                  "Foxglove connections served at once; more get HTTP 503")
      ->check(CLI::Range(1u, 1024u).description(""))
      ->type_name("N (1..1024)")
      ->default_str("16");
  app->add_option("--foxglove-tls", args.tls,
                  "Serve --foxglove as wss:// (TLS 1.2 or later) with the PEM certificate chain CERT and its "
                  "private key KEY")
      ->expected(2)
      ->type_name("CERT KEY");
  return o;
}

foxglove::HostedService hosted_service(const std::string& node, const std::string& name,
                                       const std::string& type,
                                       std::function<Result<Bytes>(std::span<const std::byte>)> call) {
  foxglove::HostedService h;
  h.spec = foxglove::service_spec(node, name, type);
  h.call = [call = std::move(call)](std::string_view request) -> Result<std::string> {
    Result<Bytes> reply = call({reinterpret_cast<const std::byte*>(request.data()), request.size()});
    if (!reply) return reply.error();
    return std::string(reinterpret_cast<const char*>(reply.value().data()), reply.value().size());
  };
  return h;
}

int foxglove_exit_status(const Error& error) {
  return error.code == ErrorCode::InvalidArgument ? 2 : 1;
}

Result<std::unique_ptr<foxglove::Server>> start_foxglove(const char* command, const FoxgloveArgs& args,
                                                         std::vector<foxglove::ChannelSpec> channels,
                                                         control::Steering* steering, const std::string& node,
                                                         std::vector<foxglove::HostedService> hosted) {
  foxglove::ServerOptions options;
  if (Status st = foxglove::parse_listen_address(args.address.value_or(""), options); !st) return st.error();
  if (!args.token_file.empty()) {
    Result<std::string> token = foxglove::read_token_file(args.token_file);
    if (!token) return token.error();
    options.token = std::move(token.value());
  } else if (const char* env = std::getenv("RBSIM_FOXGLOVE_TOKEN"); env != nullptr && *env != '\0') {
    if (const std::string problem = foxglove::token_problem(env); !problem.empty())
      return Error{"RBSIM_FOXGLOVE_TOKEN: " + problem, ErrorCode::InvalidArgument};
    options.token = env;
  }
  if (options.token.empty() && !args.insecure && !foxglove::is_loopback(options.address)) {
    return Error{
        "--foxglove " + *args.address +
            " serves other hosts, who could watch and steer without a token: "
            "add --foxglove-token-file FILE (or set RBSIM_FOXGLOVE_TOKEN), or pass --foxglove-insecure",
        ErrorCode::InvalidArgument};
  }
  options.allow_insecure = args.insecure;
  if (args.tls.size() == 2) {
    options.tls_cert = args.tls[0];
    options.tls_key = args.tls[1];
  }
  const bool tls = !options.tls_cert.empty();
  options.max_clients = args.max_clients;
  options.steering = steering;
  options.node = node;
  options.hosted_services = std::move(hosted);
  auto server = foxglove::Server::start(options, std::move(channels));
  if (!server) return server.error();
  const std::uint16_t port = server.value()->port();
  // The line tests and scripts read the port from (port 0 picks one).
  RBSIM_LOG(Info, "%s: foxglove: listening on %s%s\n", command,
            foxglove::websocket_url(options.address, port, tls).c_str(),
            options.token.empty() ? ""
            : args.print_token    ? " (token required)"
                                  : " (token required: add /?token=TOKEN, or --print-token to print it)");
  // A browser cannot connect to 0.0.0.0 (or ::): the link names this host's loopback instead.
  std::string host = options.address;
  if (host == "0.0.0.0") host = "127.0.0.1";
  if (host == "::") host = "::1";
  std::string url = foxglove::websocket_url(host, port, tls);
  if (!options.token.empty() && args.print_token) url = foxglove::url_with_token(url, options.token);
  RBSIM_LOG(Info, "%s: foxglove: open %s\n", command, foxglove::foxglove_app_link(url).c_str());
  RBSIM_LOG(Info, "%s: foxglove: layout %s (Foxglove: Layouts > Import from file)\n", command,
            bundled_path("foxglove-layout.json", "docs/foxglove-layout.json").c_str());
  return server;
}

std::string foxglove_summary(const foxglove::Server& server) {
  const foxglove::ServerStats s = server.stats();
  std::string line = "foxglove: " + std::to_string(s.clients) + plural(s.clients, " client", " clients") +
                     ", " + std::to_string(s.published) + " messages queued, " + std::to_string(s.dropped) +
                     " dropped for slow clients";
  if (s.disconnected > 0) line += ", " + std::to_string(s.disconnected) + " disconnected for not reading";
  if (s.refused > 0) line += ", " + std::to_string(s.refused) + " handshakes refused";
  if (s.unauthorized > 0) line += ", " + std::to_string(s.unauthorized) + " refused without the right token";
  if (s.rate_limited > 0) line += ", " + std::to_string(s.rate_limited) + " rate-limited";
  if (s.full > 0) line += ", " + std::to_string(s.full) + " refused over --foxglove-max-clients";
  if (s.handshake_timeouts > 0)
    line += ", " + std::to_string(s.handshake_timeouts) + " closed for an unfinished handshake";
  if (s.requests > 0) line += ", " + std::to_string(s.requests) + plural(s.requests, " request", " requests");
  if (s.refused_requests > 0) line += ", " + std::to_string(s.refused_requests) + " requests refused";
  return line;
}

}  // namespace rbsim::cli
