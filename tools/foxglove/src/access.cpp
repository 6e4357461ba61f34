// Access to the Foxglove server: tokens (read, checked, presented, compared) and the gate that
// admits or refuses a handshake (access.hpp); loopback addresses.
#include "access.hpp"

#include <arpa/inet.h>
#include <openssl/crypto.h>
#include <openssl/sha.h>
#include <sys/stat.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <memory>
#include <sstream>

namespace rbsim::foxglove {

std::string token_problem(std::string_view token) {
  if (token.size() < kMinTokenLength)
    return "a token must be at least " + std::to_string(kMinTokenLength) + " characters long (it has " +
           std::to_string(token.size()) + ")";
  for (const char ch : token) {
    const auto c = static_cast<unsigned char>(ch);
    if (c < 33 || c > 126) return "a token must be printable ASCII without spaces";
  }
  return {};
}

Result<std::string> read_token_file(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0)
    return Error{"token file " + path + ": " + std::strerror(errno), ErrorCode::InvalidArgument};
  if (!S_ISREG(st.st_mode))
    return Error{"token file " + path + ": not a regular file", ErrorCode::InvalidArgument};
  if ((st.st_mode & (S_IRWXG | S_IRWXO)) != 0) {
    return Error{
        "token file " + path +
            ": group or others may access it; a token file must be private to its owner (chmod 600 " + path +
            ")",
        ErrorCode::InvalidArgument};
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) return Error{"token file " + path + ": cannot be read", ErrorCode::InvalidArgument};
  std::ostringstream text;
  text << in.rdbuf();
  std::string token = text.str();
  if (!token.empty() && token.back() == '\n') token.pop_back();
  if (!token.empty() && token.back() == '\r') token.pop_back();
  if (const std::string problem = token_problem(token); !problem.empty())
    return Error{"token file " + path + ": " + problem, ErrorCode::InvalidArgument};
  return token;
}

bool is_loopback(std::string_view address) {
  const std::string a(address);
  in_addr a4{};
  if (inet_pton(AF_INET, a.c_str(), &a4) == 1) return (ntohl(a4.s_addr) >> 24) == 127;
  in6_addr a6{};
  if (inet_pton(AF_INET6, a.c_str(), &a6) != 1) return false;
  if (IN6_IS_ADDR_LOOPBACK(&a6)) return true;
  return IN6_IS_ADDR_V4MAPPED(&a6) && a6.s6_addr[12] == 127;
}

namespace detail {

namespace {

int hex_digit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

std::string percent_decode(std::string_view s) {
  std::string out;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '%' && i + 2 < s.size()) {
      const int hi = hex_digit(s[i + 1]), lo = hex_digit(s[i + 2]);
      if (hi >= 0 && lo >= 0) {
        out.push_back(static_cast<char>(hi * 16 + lo));
        i += 2;
        continue;
      }
    }
    out.push_back(s[i]);  // '+' stays '+': a token has no spaces
  }
  return out;
}

}  // namespace

std::optional<std::string> presented_token(std::string_view resource, std::string_view authorization) {
  constexpr std::string_view kBearer = "Bearer ";
  if (authorization.size() > kBearer.size()) {
    bool bearer = true;
    for (std::size_t i = 0; i < kBearer.size(); ++i) {
      const char c = authorization[i];
      bearer = bearer && (c == kBearer[i] || (c >= 'a' && c <= 'z' && c - 32 == kBearer[i]));
    }
    if (bearer) return std::string(authorization.substr(kBearer.size()));
  }
  const auto q = resource.find('?');
  if (q == std::string_view::npos) return std::nullopt;
  std::string_view query = resource.substr(q + 1);
  if (const auto hash = query.find('#'); hash != std::string_view::npos) query = query.substr(0, hash);
  while (!query.empty()) {
    const auto amp = query.find('&');
    const std::string_view pair = query.substr(0, amp);
    if (pair.starts_with("token=")) return percent_decode(pair.substr(6));
    if (amp == std::string_view::npos) break;
    query = query.substr(amp + 1);
  }
  return std::nullopt;
}

bool same_token(std::string_view a, std::string_view b) {
  unsigned char da[SHA256_DIGEST_LENGTH], db[SHA256_DIGEST_LENGTH];
  SHA256(reinterpret_cast<const unsigned char*>(a.data()), a.size(), da);
  SHA256(reinterpret_cast<const unsigned char*>(b.data()), b.size(), db);
  return CRYPTO_memcmp(da, db, sizeof da) == 0;
}

AccessGate::AccessGate(const ServerOptions& options)
    : token_(options.token),
      failures_max_(options.auth_failures_max),
      window_(std::chrono::duration_cast<Clock::duration>(
          std::chrono::duration<double>(options.auth_failure_window_s))),
      max_clients_(options.max_clients) {}

AccessGate::Verdict AccessGate::check(const std::string& remote, std::string_view resource,
                                      std::string_view authorization, std::size_t admitted,
                                      Clock::time_point now) {
  if (!token_.empty()) {
    auto it = failures_.find(remote);
    if (it != failures_.end()) {
      while (!it->second.empty() && now - it->second.front() >= window_) it->second.pop_front();
      if (it->second.empty()) {
        failures_.erase(it);
        it = failures_.end();
      } else if (failures_max_ > 0 && it->second.size() >= failures_max_) {
        return Verdict::RateLimited;
      }
    }
    const std::optional<std::string> presented = presented_token(resource, authorization);
    if (!presented || !same_token(*presented, token_)) {
      if (failures_max_ > 0) {
        if (it == failures_.end()) {
          forget_old(now);
          it = failures_.emplace(remote, std::deque<Clock::time_point>{}).first;
        }
        it->second.push_back(now);
        while (it->second.size() > failures_max_) it->second.pop_front();
      }
      return Verdict::Unauthorized;
    }
  }
  if (admitted >= max_clients_) return Verdict::Full;
  return Verdict::Admit;
}

// Bounds the table: past 4,096 addresses, those whose failures are all older than the window go,
// then (a flood from many addresses) the whole table: the limit then starts afresh.
void AccessGate::forget_old(Clock::time_point now) {
  constexpr std::size_t kMaxAddresses = 4096;
  if (failures_.size() < kMaxAddresses) return;
  std::erase_if(failures_, [&](const auto& entry) { return now - entry.second.back() >= window_; });
  if (failures_.size() >= kMaxAddresses) failures_.clear();
}

std::function<Admission(const Handshake&)> admission(const ServerOptions& options,
                                                     std::function<void(AccessGate::Verdict)> counted) {
  auto gate = std::make_shared<AccessGate>(options);
  const std::uint32_t max_clients = options.max_clients;
  return [gate, counted = std::move(counted), max_clients](const Handshake& h) {
    const AccessGate::Verdict v =
        gate->check(h.remote_address, h.resource, h.authorization, h.admitted, AccessGate::Clock::now());
    if (v == AccessGate::Verdict::Admit) return Admission{};
    if (counted) counted(v);
    switch (v) {
      case AccessGate::Verdict::Unauthorized:
        return Admission{401,
                         "rbsim: this Foxglove server needs its token: ws://HOST:PORT/?token=TOKEN or an "
                         "Authorization: Bearer TOKEN header\n"};
      case AccessGate::Verdict::RateLimited:
        return Admission{429, "rbsim: too many failed attempts from this address; try again later\n"};
      default:
        return Admission{503, "rbsim: this Foxglove server already has its " + std::to_string(max_clients) +
                                  " clients (--foxglove-max-clients)\n"};
    }
  };
}

}  // namespace detail

}  // namespace rbsim::foxglove
