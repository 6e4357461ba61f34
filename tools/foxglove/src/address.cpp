// The server's listen address and the links a command prints (rbsim/foxglove.hpp).
#include <arpa/inet.h>

#include <cstdio>
#include <string>

#include "rbsim/foxglove.hpp"

namespace rbsim::foxglove {

namespace {
// RFC 3986: every byte but the unreserved characters as %XX.
std::string percent_encode(std::string_view text) {
  std::string out;
  for (const char ch : text) {
    const auto c = static_cast<unsigned char>(ch);
    if ((c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '-' || c == '_' ||
        c == '.' || c == '~') {
      out.push_back(ch);
    } else {
      char hex[4];
      std::snprintf(hex, sizeof hex, "%%%02X", c);
      out += hex;
    }
  }
  return out;
}
}  // namespace

Status parse_listen_address(std::string_view text, ServerOptions& options) {
  std::string address = "127.0.0.1";
  std::string_view port_text = text;
  if (!text.empty() && text.front() == '[') {
    const auto close = text.find("]:");
    if (close == std::string_view::npos) return Error{"\"" + std::string(text) + "\": expected [IPv6]:PORT"};
    address = std::string(text.substr(1, close - 1));
    port_text = text.substr(close + 2);
    in6_addr a6{};
    if (inet_pton(AF_INET6, address.c_str(), &a6) != 1)
      return Error{"\"" + address + "\" is not an IPv6 address"};
  } else if (const auto colon = text.rfind(':'); colon != std::string_view::npos) {
    address = std::string(text.substr(0, colon));
    port_text = text.substr(colon + 1);
    if (address == "localhost") address = "127.0.0.1";
    in_addr a4{};
    if (inet_pton(AF_INET, address.c_str(), &a4) != 1)
      return Error{"\"" + address + "\" is not an IPv4 address (use 127.0.0.1, 0.0.0.0 or [IPv6])"};
  }
  if (port_text.empty() || port_text.size() > 5 ||
      port_text.find_first_not_of("0123456789") != std::string_view::npos) {
    return Error{"\"" + std::string(text) + "\": expected [ADDR:]PORT with PORT in 0..65535"};
  }
  const unsigned long port = std::stoul(std::string(port_text));
  if (port > 65535) return Error{"port " + std::string(port_text) + " is out of range (0..65535)"};
  options.address = address;
  options.port = static_cast<std::uint16_t>(port);
  return Ok{};
}

std::string websocket_url(std::string_view address, std::uint16_t port, bool tls) {
  const bool v6 = address.find(':') != std::string_view::npos;
  return (tls ? "wss://" : "ws://") + (v6 ? "[" + std::string(address) + "]" : std::string(address)) + ":" +
         std::to_string(port);
}

std::string foxglove_app_link(std::string_view url) {
  return "https://app.foxglove.dev/?ds=foxglove-websocket&ds.url=" + percent_encode(url);
}

std::string url_with_token(std::string_view url, std::string_view token) {
  return std::string(url) + "/?token=" + percent_encode(token);
}

}  // namespace rbsim::foxglove
