// libFuzzer target: the service and parameter codecs (rbsim/interfaces.hpp,
// rbsim/simulation_interfaces.hpp), what a service server decodes from any client. The first input byte picks
// one of the types (interface_types.hpp); the rest is the CDR given to its decoder, which returns a value or
// a clean error. A value that decodes must survive a round trip: its encoding decodes to a value whose
// encoding is the same bytes (bytes, not values, compare: NaN is not equal to itself).
#include <cstddef>
#include <cstdint>
#include <span>

#include "interface_types.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::span<const std::byte> cdr(reinterpret_cast<const std::byte*>(data + 1), size - 1);
  rbsim::fuzz::with_interface(data[0] % rbsim::fuzz::kInterfaceCount, [&]<class T>() {
    T value;
    if (!decode(cdr, value).ok()) return;  // msgs' or simulation's: argument-dependent lookup
    rbsim::Bytes once, twice;
    encode(value, once);
    T again;
    if (!decode(once, again).ok()) __builtin_trap();
    encode(again, twice);
    if (once != twice) __builtin_trap();
  });
  return 0;
}
