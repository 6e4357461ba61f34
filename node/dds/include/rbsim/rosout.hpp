// The one path of the lines a DDS command (node, record, replay, bridge) prints on stderr: each
// goes to stderr and, while a Rosout lives, also to /rosout as rcl_interfaces/msg/Log (what rcl's
// rosout handler publishes for a node: level, the node's logger name, the text, file, function,
// line, stamped in the node's clock), with rcl's rosout QoS (reliable, transient local, keep last
// 1000, lifespan 10 s).
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <source_location>
#include <string>
#include <string_view>

#include "rbsim/dds.hpp"
#include "rbsim/ros_graph_msgs.hpp"

namespace rbsim::node {

using LogLevel = msgs::LogLevel;

// Writes `line` and a newline to stderr, then publishes it on the current Rosout, if any.
void log(LogLevel level, std::string_view line, std::source_location where = std::source_location::current());
// printf-style log() for the call sites that format (RBSIM_LOG).
[[gnu::format(printf, 3, 4)]] void logf(LogLevel level, std::source_location where, const char* format, ...);
#define RBSIM_LOG(level, ...) \
  ::rbsim::node::logf(::rbsim::node::LogLevel::level, std::source_location::current(), __VA_ARGS__)

// A node's /rosout publisher. While it lives it is the process's current one (the last created).
class Rosout {
 public:
  using Clock = std::function<std::int64_t()>;  // the node's time now, ns since its epoch
  // `clock`: null means the system clock (ROS time without use_sim_time).
  static Result<std::unique_ptr<Rosout>> create(const Participant& participant, Clock clock = nullptr);
  ~Rosout();
  Rosout(const Rosout&) = delete;
  Rosout& operator=(const Rosout&) = delete;
  // `rbsim node` switches to simulated time once it has a world.
  void set_clock(Clock clock);
  [[nodiscard]] Status publish(LogLevel level, std::string_view text, const std::source_location& where);
  std::uint64_t published() const;
  Publisher& publisher() { return publisher_; }

 private:
  Rosout(Publisher publisher, std::string name, Clock clock)
      : publisher_(std::move(publisher)), name_(std::move(name)), clock_(std::move(clock)) {}
  mutable std::mutex mutex_;
  Publisher publisher_;
  std::string name_;  // the node's logger name
  Clock clock_;
  Bytes cdr_;
  std::uint64_t published_ = 0;
};

// rcutils' function name from a std::source_location one ("int ns::f(int)" -> "f").
std::string_view function_name(std::string_view pretty);

}  // namespace rbsim::node
