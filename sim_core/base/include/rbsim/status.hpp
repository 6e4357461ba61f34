// Errors as values: Result<T> holds a T or an Error, Status is a Result with no value. Every
// layer's I/O paths return them (the scene loader, the sinks, the MCAP and log tools); internal
// invariants are assertions instead (rbsim/assert.hpp).
#pragma once

#include <string>
#include <utility>
#include <variant>

namespace rbsim {

struct Error {
  std::string message;
};

template <class T>
class [[nodiscard]] Result {
 public:
  Result(T value) : v_(std::move(value)) {}      // NOLINT(google-explicit-constructor)
  Result(Error error) : v_(std::move(error)) {}  // NOLINT(google-explicit-constructor)
  bool ok() const { return v_.index() == 0; }
  explicit operator bool() const { return ok(); }
  T& value() { return std::get<0>(v_); }
  const T& value() const { return std::get<0>(v_); }
  T& operator*() { return value(); }
  T* operator->() { return &value(); }
  const Error& error() const { return std::get<1>(v_); }

 private:
  std::variant<T, Error> v_;
};

struct Ok {};
using Status = Result<Ok>;

}  // namespace rbsim
