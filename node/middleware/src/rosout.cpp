// stderr and /rosout, one path (rbsim/rosout.hpp).
#include "rbsim/rosout.hpp"
#include "rbsim/time.hpp"

#include <atomic>
#include <chrono>
#include <cstdio>

namespace rbsim::node {

namespace {
// The process's current Rosout. Guarded: a line may be logged while another thread ends the
// Rosout (the relay's and the server's threads never log, but a destructor may run anywhere).
std::mutex g_current_mutex;
Rosout* g_current = nullptr;

}  // namespace

std::string_view function_name(std::string_view pretty) {
  // GCC: "int rbsim::cli::{anonymous}::node_command(const NodeArgs&)"; rcutils logs __func__.
  const auto paren = pretty.find('(');
  if (paren != std::string_view::npos) pretty = pretty.substr(0, paren);
  const auto colon = pretty.rfind(':');
  const auto space = pretty.rfind(' ');
  const auto cut = std::max(colon == std::string_view::npos ? 0 : colon + 1,
                            space == std::string_view::npos ? 0 : space + 1);
  return pretty.substr(cut);
}

namespace {
// The print hook (rbsim/print.hpp): a printed line, after stderr, to the current Rosout.
void to_current(LogLevel level, std::string_view line, const std::source_location& where) {
  std::lock_guard lock(g_current_mutex);
  if (g_current == nullptr) return;
  if (Status st = g_current->publish(level, line, where); !st) {
    std::fprintf(stderr, "rbsim: warning: /rosout: %s\n", st.error().message.c_str());
  }
}
}  // namespace

Result<std::unique_ptr<Rosout>> Rosout::create(const Participant& participant, Clock clock) {
  // rcl_qos_profile_rosout_default.
  constexpr QosSpec kQos{true, false, 1000};
  EndpointOptions options;
  options.lifespan_ns = 10'000'000'000;
  auto pub = Publisher::create(participant, RawTopic{"/rosout", std::string(msgs::kLogType)}, kQos, options);
  if (!pub) return pub.error();
  std::unique_ptr<Rosout> rosout(
      new Rosout(std::move(pub.value()), participant.node().logger_name(), std::move(clock)));
  std::lock_guard lock(g_current_mutex);
  g_current = rosout.get();
  print::set_hook(&to_current);
  return rosout;
}

Rosout::~Rosout() {
  std::lock_guard lock(g_current_mutex);
  if (g_current == this) g_current = nullptr;
}

void Rosout::set_clock(Clock clock) {
  std::lock_guard lock(mutex_);
  clock_ = std::move(clock);
}

Status Rosout::publish(LogLevel level, std::string_view text, const std::source_location& where) {
  std::lock_guard lock(mutex_);
  const std::int64_t now = clock_ ? clock_() : wall_ns();
  msgs::LogMessage m;
  m.stamp = msgs::time_from_ns(static_cast<std::uint64_t>(now));
  m.level = level;
  m.name = name_;
  m.msg = text;
  m.file = where.file_name();
  m.function = function_name(where.function_name());
  m.line = where.line();
  msgs::encode_log(m, cdr_);
  Status st = publisher_.publish(cdr_);
  if (st) ++published_;
  return st;
}

std::uint64_t Rosout::published() const {
  std::lock_guard lock(mutex_);
  return published_;
}

}  // namespace rbsim::node
