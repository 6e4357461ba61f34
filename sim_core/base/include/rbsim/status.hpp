// Errors as values, the one error vocabulary of every layer: Result<T> holds a T or an Error,
// Status is a Result with no value. An Error is a message and a code: most say only Failed (the
// default, so `Error{"message"}` is the whole of it); the MCAP library's carry what went wrong in
// the file (BadMagic, Truncated, ...) for callers that act on it (recover, doctor, the readers).
// Every layer's I/O paths return them (the scene loader, the sinks, the MCAP and log tools);
// internal invariants are assertions instead (rbsim/assert.hpp).
#pragma once

#include <concepts>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <variant>

namespace rbsim {

enum class ErrorCode : std::uint8_t {
  Failed,           // any error without a more specific code
  NotOpen,          // call on a closed writer/reader
  InvalidArgument,  // e.g. unknown channel id
  IoError,          // open/read/write failed
  BadMagic,         // missing or wrong magic bytes: not an MCAP file
  Truncated,        // file or record ends before the data it announces
  Malformed,        // structurally invalid record or section
  CrcMismatch,
  UnsupportedCompression,
  DecompressionFailed,
  Cancelled,  // gave up because the user asked to stop (Ctrl-C): not a failure of its own
};

struct Error {
  std::string message;
  ErrorCode code = ErrorCode::Failed;
};

struct Ok {};

template <class T>
class [[nodiscard]] Result {
 public:
  Result()  // a default Status is ok
      requires std::same_as<T, Ok>
  = default;
  Result(T value) : v_(std::move(value)) {}      // NOLINT(google-explicit-constructor)
  Result(Error error) : v_(std::move(error)) {}  // NOLINT(google-explicit-constructor)
  bool ok() const { return v_.index() == 0; }
  explicit operator bool() const { return ok(); }
  T& value() & { return std::get<0>(v_); }
  const T& value() const& { return std::get<0>(v_); }
  T&& value() && { return std::get<0>(std::move(v_)); }
  T& operator*() & { return value(); }
  const T& operator*() const& { return value(); }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }
  // Only when !ok(): the message and the code.
  const Error& error() const { return std::get<1>(v_); }
  // The error's code, none when ok(): `st.code() == ErrorCode::Truncated` is false for an ok st.
  std::optional<ErrorCode> code() const {
    if (ok()) return std::nullopt;
    return error().code;
  }

 private:
  std::variant<T, Error> v_;
};

using Status = Result<Ok>;

// The one way to say where an error happened: `context` put before its message, its code kept
// (`with_context(path + ": ", st.error())`), so an outer layer adds words, never loses what a
// caller acts on. `code` replaces the code only where a caller's answer must stay another one.
[[nodiscard]] inline Error with_context(std::string context, const Error& error,
                                        std::optional<ErrorCode> code = std::nullopt) {
  context += error.message;
  return Error{std::move(context), code.value_or(error.code)};
}

}  // namespace rbsim
