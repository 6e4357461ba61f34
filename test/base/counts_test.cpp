// Counts in words (rbsim/counts.hpp): the one plural rule and the one digit grouping every
// command's summary uses.
#include "rbsim/counts.hpp"

#include <gtest/gtest.h>

#include <cstddef>
#include <cstdint>
#include <string>

namespace rbsim {
namespace {

TEST(RbsimCounts, PluralIsTheSingularForExactlyOne) {
  EXPECT_STREQ(plural(0, "body", "bodies"), "bodies");
  EXPECT_STREQ(plural(1, "body", "bodies"), "body");
  EXPECT_STREQ(plural(2, "body", "bodies"), "bodies");
  EXPECT_STREQ(plural(std::int64_t{-1}, "step", "steps"), "steps");
  EXPECT_STREQ(plural(std::size_t{1}, " topic, ", " topics, "), " topic, ");
  EXPECT_STREQ(plural(std::uint64_t{1000}, "", "s"), "s");
  EXPECT_EQ(std::string("pass") + plural(3u, "", "es"), "passes");
  static_assert(plural(1, "a", "b")[0] == 'a');  // usable where a constant is
}

TEST(RbsimCounts, GroupDigitsPutsACommaBetweenGroupsOfThree) {
  EXPECT_EQ(group_digits(0), "0");
  EXPECT_EQ(group_digits(999), "999");
  EXPECT_EQ(group_digits(1000), "1,000");
  EXPECT_EQ(group_digits(123456), "123,456");
  EXPECT_EQ(group_digits(1234567), "1,234,567");
  EXPECT_EQ(group_digits(UINT64_MAX), "18,446,744,073,709,551,615");
}

}  // namespace
}  // namespace rbsim
