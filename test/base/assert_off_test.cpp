// RBSIM_ASSERT with NDEBUG (the main and Release builds): the condition is not even evaluated and
// a false one does not stop execution. This file is compiled with NDEBUG in every build
// (test/base/CMakeLists.txt); assert_test.cpp checks the side with assertions on.
#include <gtest/gtest.h>

#ifndef NDEBUG
#error "assert_off_test.cpp must be compiled with NDEBUG"
#endif

#include "rbsim/assert.hpp"

namespace rbsim {
namespace {

TEST(RbsimAssert, ConditionIsNotEvaluatedWithNdebug) {
  int evaluated = 0;
  RBSIM_ASSERT(++evaluated == 1, "never checked");
  EXPECT_EQ(evaluated, 0);
}

TEST(RbsimAssert, FalseConditionDoesNotStopWithNdebug) {
  const int values = 3;
  RBSIM_ASSERT(values < 2, "compiled out");
  SUCCEED() << "execution went on past a false condition";
}

}  // namespace
}  // namespace rbsim
