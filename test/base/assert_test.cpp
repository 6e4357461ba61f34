// RBSIM_ASSERT: on without NDEBUG (Debug builds, the sanitizer stage), where a failed invariant
// aborts with where and why; with NDEBUG (the main and Release builds) its condition is not even
// evaluated. Each test checks whichever of the two this build is.
#include "rbsim/assert.hpp"

#include <gtest/gtest.h>

namespace rbsim {
namespace {

#ifdef NDEBUG
constexpr bool kAssertionsOn = false;
#else
constexpr bool kAssertionsOn = true;
#endif

TEST(RbsimAssert, ConditionIsEvaluatedOnlyWhenAssertionsAreOn) {
  int evaluated = 0;
  RBSIM_ASSERT(++evaluated == 1, "checked once");
  EXPECT_EQ(evaluated, kAssertionsOn ? 1 : 0);
}

TEST(RbsimAssertDeathTest, FailedConditionAbortsNamingItAndTheMessage) {
  const int values = 3;
  if (kAssertionsOn) {
    EXPECT_DEATH(
        RBSIM_ASSERT(values < 2, "an index within its values"),
        "assert_test.cpp:[0-9]+: internal error: an index within its values \\(values < 2 failed\\)");
  } else {
    RBSIM_ASSERT(values < 2, "an index within its values");  // compiled out: execution goes on
    SUCCEED();
  }
}

}  // namespace
}  // namespace rbsim
