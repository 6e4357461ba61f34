// The middleware seam's in-memory backend: participants of one process on a shared MemoryNetwork,
// no network, no threads of its own. Semantics as rbsim uses DDS's:
//   - a publisher and a subscription match when their ROS topic names and types are equal and the
//     subscription asks for no more durability than is offered (a transient-local subscription does
//     not match a volatile publisher);
//   - every endpoint is reliable: a publish reaches every matched subscription's queue at once
//     (publish never blocks, flush has nothing to wait for);
//   - a subscription's queue keeps the last `depth` samples (keep last) or up to kKeepAllLimit
//     (keep all); an older sample pushed out is counted in lost();
//   - a transient-local publisher keeps its last `depth` samples (keep all: up to kKeepAllLimit)
//     and hands them to a transient-local subscription created later; a volatile one keeps none;
//   - a received sample carries its publisher's stable 16-byte id, the wall-clock time it was
//     published (source_time_ns) and the QoS it offers;
//   - a client's request reaches every server of the same service name and type, the reply only
//     the calling client (RequestHeader: the client's id and its sequence number); a server counts
//     its requests as the DDS server does (queue_limit, max_request_bytes, malformed bodies, a
//     client gone before its reply); a client is always matched, so nothing is ever pending;
//   - graph(): the nodes and the endpoints listed on the graph (EndpointOptions::in_graph,
//     ServiceOptions::in_graph), for tests.
// Thread-safe: one mutex per network. Waits are condition variables with a timeout.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "rbsim/middleware.hpp"

namespace rbsim::node {

class MemoryNetwork {
 public:
  // The bound of a keep-all queue or history: more pushes out the oldest (counted as lost).
  static constexpr std::size_t kKeepAllLimit = 100'000;

  struct Endpoint {
    enum class Kind : std::uint8_t { Publisher, Subscription, ServiceServer, ServiceClient };
    Kind kind = Kind::Publisher;
    std::string name;  // the ROS topic or service name
    std::string type;  // "pkg/msg/Name" or "pkg/srv/Name"
    bool operator==(const Endpoint&) const = default;
  };
  struct Node {
    NodeName name;
    std::vector<Endpoint> endpoints;  // in the order created
  };

  MemoryNetwork();
  ~MemoryNetwork();
  MemoryNetwork(const MemoryNetwork&) = delete;
  MemoryNetwork& operator=(const MemoryNetwork&) = delete;

  // The nodes on the network now (participants, in the order created), each with its endpoints.
  std::vector<Node> graph() const;

  struct State;  // node/memory/src
  State& state() const { return *state_; }

 private:
  std::unique_ptr<State> state_;
};

// A participant (one node) on `network`.
Result<Participant> create_memory_participant(std::shared_ptr<MemoryNetwork> network,
                                              const NodeName& node = {});

}  // namespace rbsim::node
