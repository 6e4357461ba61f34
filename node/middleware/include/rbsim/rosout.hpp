// /rosout for the lines a ROS 2 command (node, record, replay, bridge) prints: each goes to stderr
// through base's print::log (rbsim/print.hpp) and, while a Rosout lives (it is the print hook),
// also to /rosout as rcl_interfaces/msg/Log (what rcl's
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

#include "rbsim/middleware.hpp"
#include "rbsim/print.hpp"
#include "rbsim/ros_graph_msgs.hpp"

namespace rbsim::node {

using LogLevel = msgs::LogLevel;

// stderr, then the current Rosout, if any (base's print::log, whose hook the Rosout is).
using print::log;
using print::logf;

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
