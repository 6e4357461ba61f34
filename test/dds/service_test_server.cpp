// A service server for test/dds/service_client.py (an independent client on Python cyclonedds):
//   service_test_server DOMAIN NAMESPACE
// serves NAMESPACE/step (rbsim_msgs/srv/Step: step = 10 * steps, message "<guid>:<seq>" of the
// request header it got) and NAMESPACE/get_parameters (rcl_interfaces/srv/GetParameters: for each
// name an INTEGER value of its length, with the name as string_value, 0.5 * length as double_value
// and [name, name] as string_array_value), prints "READY", serves until stdin closes (at most 60 s),
// then prints "STATS received=.. answered=.. malformed=.. client_gone=.. client_unmatched=.. pending=..
// queued=..".
#include <poll.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "rbsim/dds.hpp"
#include "rbsim/interfaces.hpp"
#include "rbsim/service.hpp"
#include "step_handler.hpp"

namespace {

using namespace rbsim;

bool get_parameters(const node::RequestHeader&, std::span<const std::byte> request, Bytes& reply) {
  msgs::GetParametersRequest req;
  msgs::GetParametersResponse res;
  if (!msgs::decode(request, req).ok()) return false;  // nothing to say in this response type
  for (const std::string& name : req.names) {
    msgs::ParameterValue v;
    v.type = msgs::ParameterType::Integer;
    v.integer_value = static_cast<std::int64_t>(name.size());
    v.string_value = name;
    v.double_value = 0.5 * static_cast<double>(name.size());
    v.string_array_value = {name, name};
    res.values.push_back(v);
  }
  msgs::encode(res, reply);
  return true;
}

bool stdin_closed() {
  pollfd p{0, POLLIN, 0};
  if (::poll(&p, 1, 0) <= 0) return false;
  char buf[256];
  return ::read(0, buf, sizeof buf) <= 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: service_test_server DOMAIN NAMESPACE\n");
    return 2;
  }
  auto participant = node::create_dds_participant(static_cast<std::uint32_t>(std::atoi(argv[1])));
  if (!participant) {
    std::fprintf(stderr, "%s\n", participant.error().message.c_str());
    return 1;
  }
  const std::string ns = argv[2];
  auto step_server = node::ServiceServer::create(participant.value(), ns + "/step", "rbsim_msgs/srv/Step");
  auto params_server = node::ServiceServer::create(participant.value(), ns + "/get_parameters",
                                                   "rcl_interfaces/srv/GetParameters");
  if (!step_server || !params_server) {
    std::fprintf(stderr, "cannot create the services\n");
    return 1;
  }
  std::printf("READY\n");
  std::fflush(stdout);
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (std::chrono::steady_clock::now() < end && !stdin_closed()) {
    step_server.value().serve(node::test::step_handler, 64);
    params_server.value().serve(get_parameters, 64);
    step_server.value().wait(0.001);
  }
  const node::ServiceStats s = step_server.value().stats();
  std::printf(
      "STATS received=%llu answered=%llu malformed=%llu client_gone=%llu client_unmatched=%llu pending=%zu "
      "queued=%zu\n",
      static_cast<unsigned long long>(s.received), static_cast<unsigned long long>(s.answered),
      static_cast<unsigned long long>(s.malformed), static_cast<unsigned long long>(s.client_gone),
      static_cast<unsigned long long>(s.client_unmatched), s.pending, s.queued);
  return 0;
}
