// The seam's tests run on every backend: the in-memory one and Cyclone DDS (on the loopback
// configuration, its own domain, topic names of this process alone). A test's participants share
// one network (memory) or domain (DDS).
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cstddef>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "rbsim/dds.hpp"
#include "rbsim/memory_middleware.hpp"
#include "rbsim/middleware.hpp"

namespace rbsim::node::test {

inline constexpr std::uint32_t kDomain = 158;  // its own: test/dds has 143..157
inline constexpr double kPatience = 10.0;      // seconds a test waits for DDS discovery or delivery

class Backends : public ::testing::TestWithParam<std::string> {
 protected:
  bool memory() const { return GetParam() == "memory"; }
  Participant participant(const std::string& name = "seam_test") {
    const NodeName node{"/", name};
    Result<Participant> p =
        memory() ? create_memory_participant(network_, node) : create_dds_participant(kDomain, node);
    EXPECT_TRUE(p.ok()) << p.error().message;
    return std::move(p.value());
  }
  // A ROS name of this test and process alone: tests of other processes may share the domain.
  std::string name(const std::string& leaf) const {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string test = info->name();
    for (char& c : test) c = (c == '/') ? '_' : c;
    return "/seam_" + std::to_string(::getpid()) + "_" + test + "/" + leaf;
  }
  std::shared_ptr<MemoryNetwork> network_ = std::make_shared<MemoryNetwork>();
};

inline std::string backend_name(const ::testing::TestParamInfo<std::string>& info) {
  return info.param;
}

// Polls `done` until it holds or `seconds` pass (what DDS discovery and delivery need; the memory
// backend is done at once).
template <class Done>
bool eventually(Done done, double seconds = kPatience) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (!done()) {
    if (std::chrono::steady_clock::now() >= end) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return true;
}

// A rosgraph_msgs/Clock in CDR: the encapsulation header (little-endian CDR), sec, nanosec.
inline std::vector<std::byte> clock_cdr(std::uint8_t sec) {
  return {std::byte{0}, std::byte{1}, std::byte{0}, std::byte{0}, std::byte{sec}, std::byte{0},
          std::byte{0}, std::byte{0}, std::byte{0}, std::byte{0}, std::byte{0},   std::byte{0}};
}

// Takes one sample, waiting for it through a wait set (bounded).
inline bool take_within(WaitSet& waitset, Subscription& sub, Received& out, double seconds = kPatience) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (!sub.take(out)) {
    const auto left =
        std::chrono::duration_cast<std::chrono::nanoseconds>(end - std::chrono::steady_clock::now());
    if (left.count() <= 0) return false;
    if (!waitset.wait(left.count())) return false;
  }
  return true;
}

}  // namespace rbsim::node::test
