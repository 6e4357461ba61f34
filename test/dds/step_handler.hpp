// The Step handler the service tests serve (service_test.cpp in process, service_test_server.cpp
// for the Python client): steps -> step = 10 * steps, message "<guid>:<seq>" of the request
// header; a request that does not decode gets success false with the decoder's error.
#pragma once

#include <span>
#include <string>

#include "rbsim/interfaces.hpp"
#include "rbsim/service.hpp"

namespace rbsim::node::test {

inline bool step_handler(const RequestHeader& h, std::span<const std::byte> request, Bytes& reply) {
  msgs::StepRequest req;
  msgs::StepResponse res;
  if (Status st = msgs::decode(request, req); !st) {
    res.message = st.error().message;
  } else {
    res.success = true;
    res.step = 10ull * req.steps;
    res.message = std::to_string(h.guid) + ":" + std::to_string(h.seq);
  }
  msgs::encode(res, reply);
  return true;
}

}  // namespace rbsim::node::test
