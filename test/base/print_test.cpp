// base's printing path (rbsim/print.hpp): every line to the hook after stderr, formatted lines
// without their trailing newlines, the hook replaced and removed.
#include "rbsim/print.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace {

struct Line {
  rbsim::print::Level level;
  std::string text;
  unsigned line;
};
std::vector<Line> g_lines;

void keep(rbsim::print::Level level, std::string_view text, const std::source_location& where) {
  g_lines.push_back({level, std::string(text), where.line()});
}

TEST(Print, LinesReachTheHookWithLevelAndCallSite) {
  g_lines.clear();
  const rbsim::print::Hook before = rbsim::print::set_hook(&keep);
  EXPECT_EQ(before, nullptr);
  rbsim::print::log(rbsim::print::Level::Warn, "rbsim: warning: one");
  const unsigned here = __LINE__ - 1;
  RBSIM_LOG(Info, "%s: %d steps\n\n", "rbsim run", 3);
  EXPECT_EQ(rbsim::print::set_hook(nullptr), &keep);
  rbsim::print::log(rbsim::print::Level::Error, "not kept");
  ASSERT_EQ(g_lines.size(), 2u);
  EXPECT_EQ(g_lines[0].level, rbsim::print::Level::Warn);
  EXPECT_EQ(g_lines[0].text, "rbsim: warning: one");
  EXPECT_EQ(g_lines[0].line, here);
  EXPECT_EQ(g_lines[1].level, rbsim::print::Level::Info);
  EXPECT_EQ(g_lines[1].text, "rbsim run: 3 steps");
}

}  // namespace
