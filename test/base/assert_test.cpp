// RBSIM_ASSERT with assertions on, whatever this build's configuration: this file is compiled
// without NDEBUG (test/base/CMakeLists.txt), so a failed condition must abort here, naming where
// and why, in the main stage as in the sanitizer stage. assert_off_test.cpp checks the NDEBUG side.
#include "rbsim/assert.hpp"

#include <gtest/gtest.h>

#ifdef NDEBUG
#error "assert_test.cpp must be compiled with assertions on (-UNDEBUG)"
#endif

namespace rbsim {
namespace {

TEST(RbsimAssert, ConditionIsEvaluatedOnceWhenAssertionsAreOn) {
  int evaluated = 0;
  RBSIM_ASSERT(++evaluated == 1, "checked once");
  EXPECT_EQ(evaluated, 1);
}

TEST(RbsimAssertDeathTest, FailedConditionAbortsNamingItAndTheMessage) {
  const int values = 3;
  EXPECT_DEATH(RBSIM_ASSERT(values < 2, "an index within its values"),
               "assert_test.cpp:[0-9]+: internal error: an index within its values \\(values < 2 failed\\)");
}

}  // namespace
}  // namespace rbsim
