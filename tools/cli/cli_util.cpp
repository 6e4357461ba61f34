#include "cli_util.hpp"

#include <pthread.h>
#include <unistd.h>

#include <atomic>
#include <csignal>
#include <cstdio>
#include <filesystem>

#include "rbsim/counts.hpp"
#include "rbsim/print.hpp"

namespace rbsim::cli {

namespace {
std::atomic<int> g_stop_signal{0};
std::atomic<bool> g_stop_asked{false};  // request_stop()
extern "C" void on_stop_signal(int sig) {
  g_stop_signal.store(sig, std::memory_order_relaxed);
}
}  // namespace

void install_stop_handlers() {
  struct sigaction sa {};
  sa.sa_handler = on_stop_signal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
  // A parent may have started us with them blocked: one that arrived meanwhile is delivered now,
  // to the handler.
  sigset_t stops;
  sigemptyset(&stops);
  sigaddset(&stops, SIGINT);
  sigaddset(&stops, SIGTERM);
  pthread_sigmask(SIG_UNBLOCK, &stops, nullptr);
}
bool stop_requested() {
  return g_stop_signal.load(std::memory_order_relaxed) != 0 || g_stop_asked.load(std::memory_order_relaxed);
}
void request_stop() {
  g_stop_asked.store(true, std::memory_order_relaxed);
}
int stop_signal() {
  return g_stop_signal.load(std::memory_order_relaxed);
}

std::string bundled_path(const std::string& installed, const std::string& source) {
  std::error_code ec;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const std::filesystem::path beside = exe.parent_path().parent_path() / "share/rbsim" / installed;
    if (std::filesystem::exists(beside, ec)) return beside.string();
  }
  return (std::filesystem::path(RBSIM_SOURCE_SHARE) / source).string();
}

std::string format_seconds(double seconds) {
  char buf[32];
  if (seconds < 1.0) {
    std::snprintf(buf, sizeof buf, "%.1f ms", seconds * 1e3);
  } else if (seconds < 120.0) {
    std::snprintf(buf, sizeof buf, "%.2f s", seconds);
  } else {
    std::snprintf(buf, sizeof buf, "%dm%02ds", static_cast<int>(seconds) / 60,
                  static_cast<int>(seconds) % 60);
  }
  return buf;
}

Progress::Progress(std::int64_t total, Mode mode, std::chrono::milliseconds delay)
    : total_(total), start_(std::chrono::steady_clock::now()), delay_(delay) {
  enabled_ = total > 0 && (mode == Mode::Always || (mode == Mode::Auto && ::isatty(STDERR_FILENO)));
  if (mode == Mode::Always) delay_ = std::chrono::milliseconds(0);
}

Progress::~Progress() {
  finish();
}

void Progress::tick(std::int64_t done) {
  calls_ = 0;
  const auto now = std::chrono::steady_clock::now();
  if (now - start_ < delay_ || (shown_ && now - last_draw_ < std::chrono::milliseconds(100))) return;
  shown_ = true;
  last_draw_ = now;
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  const double frac = static_cast<double>(done) / static_cast<double>(total_);
  constexpr int kWidth = 30;
  const int filled = static_cast<int>(frac * kWidth);
  std::string bar(static_cast<std::size_t>(filled), '#');
  bar.resize(kWidth, '.');
  const double eta = frac > 0 ? elapsed * (1.0 - frac) / frac : 0.0;
  std::fprintf(stderr, "\r[%s] %5.1f%%  step %lld/%lld  %s elapsed, ETA %s   ", bar.c_str(), 100.0 * frac,
               static_cast<long long>(done), static_cast<long long>(total_), format_seconds(elapsed).c_str(),
               format_seconds(eta).c_str());
  std::fflush(stderr);
}

void Progress::finish() {
  if (shown_) {
    std::fprintf(stderr, "\r\033[K");
    std::fflush(stderr);
    shown_ = false;
  }
  enabled_ = false;
}

std::string count_of(std::int64_t n, const char* one, const char* many) {
  return std::to_string(n) + " " + plural(n, one, many);
}

Result<mcap::Compression> compression_option(const std::string& name, int level) {
  mcap::Compression codec = mcap::Compression::Zstd;
  if (!mcap::parse_compression(name, codec)) return Error{"--compression: unknown compression " + name};
  if (const std::string bad = mcap::check_compression_level(codec, level); !bad.empty())
    return Error{"--compression-level: " + bad};
  return codec;
}

int fail(const char* command, const std::string& message, int exit_status, std::source_location where) {
  print::log(print::Level::Error, "rbsim " + std::string(command) + ": error: " + message, where);
  return exit_status;
}

}  // namespace rbsim::cli
