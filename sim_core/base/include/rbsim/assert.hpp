// RBSIM_ASSERT(condition, message): an internal invariant, a programmer's error and never a
// user's (those are Error values). On without NDEBUG (Debug builds and the sanitizer stage of
// scripts/test): a failed assertion prints where, the condition and the message, then aborts.
// With NDEBUG the condition is not evaluated.
#pragma once

namespace rbsim::detail {
[[noreturn]] void assertion_failed(const char* condition, const char* message, const char* file, int line);
}  // namespace rbsim::detail

#ifdef NDEBUG
#define RBSIM_ASSERT(condition, message) static_cast<void>(sizeof(static_cast<bool>(condition)))
#else
#define RBSIM_ASSERT(condition, message) \
  ((condition) ? static_cast<void>(0)    \
               : ::rbsim::detail::assertion_failed(#condition, message, __FILE__, __LINE__))
#endif
