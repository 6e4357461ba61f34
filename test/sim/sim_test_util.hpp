// What the node's service tests (test/sim) share: a node name of the running test and a
// participant on the middleware a parameterised test names.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>

#include "rbsim/dds.hpp"
#include "rbsim/memory_middleware.hpp"

namespace rbsim::test {

// "<prefix>_<pid>_<test>": unique across the processes that run tests at once on one DDS domain.
inline std::string node_name(std::string_view prefix) {
  std::string test = ::testing::UnitTest::GetInstance()->current_test_info()->name();
  for (char& c : test) c = (c == '/') ? '_' : c;
  return std::string(prefix) + "_" + std::to_string(::getpid()) + "_" + test;
}

// The participant of node /<name> on "memory" (`network`) or "dds" (domain `domain`, the loopback
// configuration the tests' CYCLONEDDS_URI names).
inline node::Participant participant(std::string_view middleware,
                                     const std::shared_ptr<node::MemoryNetwork>& network,
                                     std::uint32_t domain, const std::string& name) {
  const node::NodeName n{"/", name};
  auto p = middleware == "memory" ? node::create_memory_participant(network, n)
                                  : node::create_dds_participant(domain, n);
  if (!p) throw std::runtime_error(p.error().message);
  return std::move(p.value());
}

}  // namespace rbsim::test
