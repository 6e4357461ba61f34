// Result<T>, Status and Error: the one error vocabulary. An Error built from a message alone says
// Failed; a layer that knows more (the MCAP library) gives a code, which callers read with code(),
// and with_context adds where it happened without losing it.
#include "rbsim/status.hpp"

#include <gtest/gtest.h>

#include <memory>
#include <string>

namespace rbsim {
namespace {

Status fails_with(ErrorCode code) {
  return Error{"bad bytes", code};
}

TEST(RbsimStatus, ErrorFromAMessageAloneIsFailed) {
  const Status st = Error{"no such scene"};
  ASSERT_FALSE(st.ok());
  EXPECT_FALSE(static_cast<bool>(st));
  EXPECT_EQ(st.error().message, "no such scene");
  EXPECT_EQ(st.error().code, ErrorCode::Failed);
  EXPECT_EQ(st.code(), ErrorCode::Failed);
}

TEST(RbsimStatus, DefaultAndOkStatusHaveNoCode) {
  const Status defaulted;
  const Status ok = Ok{};
  EXPECT_TRUE(defaulted.ok());
  EXPECT_TRUE(ok.ok());
  EXPECT_FALSE(ok.code().has_value());
  EXPECT_NE(ok.code(), ErrorCode::Truncated);  // safe to compare whether or not it failed
}

TEST(RbsimStatus, CodeTravelsWithTheErrorIntoAResult) {
  const Status st = fails_with(ErrorCode::Truncated);
  EXPECT_EQ(st.code(), ErrorCode::Truncated);
  const Result<int> r = st.error();  // passed on as it is: nothing translated
  EXPECT_EQ(r.code(), ErrorCode::Truncated);
  EXPECT_EQ(r.error().message, "bad bytes");
}

TEST(RbsimStatus, WithContextPutsItBeforeTheMessageAndKeepsTheCode) {
  const Status st = fails_with(ErrorCode::Truncated);
  const Error once = with_context("chunk at 42: ", st.error());
  EXPECT_EQ(once.message, "chunk at 42: bad bytes");
  EXPECT_EQ(once.code, ErrorCode::Truncated);
  const Result<int> twice = with_context("run.mcap: ", once);  // an outer layer adds its own words
  EXPECT_EQ(twice.error().message, "run.mcap: chunk at 42: bad bytes");
  EXPECT_EQ(twice.code(), ErrorCode::Truncated);
  EXPECT_EQ(with_context("", st.error()).message, "bad bytes");
}

TEST(RbsimStatus, WithContextReplacesTheCodeOnlyWhenAsked) {
  const Error e = with_context("--ros-args -p x:=1: ", Error{"not a value"}, ErrorCode::InvalidArgument);
  EXPECT_EQ(e.message, "--ros-args -p x:=1: not a value");
  EXPECT_EQ(e.code, ErrorCode::InvalidArgument);
  EXPECT_EQ(with_context("a: ", Error{"b"}).code, ErrorCode::Failed);
}

TEST(RbsimResult, HoldsAValueThatCanBeMovedOut) {
  Result<std::unique_ptr<int>> r = std::make_unique<int>(7);
  ASSERT_TRUE(r.ok());
  EXPECT_FALSE(r.code().has_value());
  EXPECT_EQ(**r, 7);
  std::unique_ptr<int> owned = std::move(r).value();
  EXPECT_EQ(*owned, 7);
}

}  // namespace
}  // namespace rbsim
