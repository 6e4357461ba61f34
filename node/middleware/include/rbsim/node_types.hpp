// The types a node uses, and what its ~/get_type_description service answers from them: rcl's
// node type cache (rcl/node_type_cache.h) and rcl_node_type_description_service_handle_request.
//
// rcl registers a type in its node's cache whenever a publisher, subscription, service or client
// is created and unregisters it when that endpoint goes; the seam does the same in one place, the
// handles' create() (rbsim/middleware.hpp, rbsim/service.hpp): each endpoint of the node
// (EndpointOptions::in_graph, ServiceOptions::in_graph, ClientOptions::in_graph) holds a
// TypeRegistration for its type (a topic's message type, a service's "pkg/srv/Name", as rcl's type
// supports register them), so the cache is what the node created, never a second list.
#pragma once

#include <cstddef>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "rbsim/type_description.hpp"

namespace rbsim::node {

class NodeTypeCache;

// A type in its node's cache for as long as this lives (move-only; empty when nothing was
// registered).
class TypeRegistration {
 public:
  TypeRegistration() = default;
  TypeRegistration(std::shared_ptr<NodeTypeCache> cache, std::string type);
  TypeRegistration(TypeRegistration&& other) noexcept = default;
  TypeRegistration& operator=(TypeRegistration&& other) noexcept;
  TypeRegistration(const TypeRegistration&) = delete;
  TypeRegistration& operator=(const TypeRegistration&) = delete;
  ~TypeRegistration();

 private:
  std::shared_ptr<NodeTypeCache> cache_;
  std::string type_;
};

// Thread-safe: endpoints come and go on any thread, the service reads it on its own.
class NodeTypeCache {
 public:
  // Registers `type` (counted: one entry however many endpoints use it) until the registration
  // goes. A type msgs cannot describe (not shipped: a recorder's foreign topic) is not registered,
  // as rcl could not describe it either.
  static TypeRegistration register_type(const std::shared_ptr<NodeTypeCache>& cache, std::string_view type);
  // The types in use, sorted.
  std::vector<std::string> types() const;
  // The type in use whose REP 2011 hash is `hash` ("RIHS01_" and 64 lower-case hex digits).
  std::optional<std::string> find(std::string_view hash) const;

 private:
  friend class TypeRegistration;
  void unregister(const std::string& type);
  struct Entry {
    std::string hash;
    std::size_t registrations = 0;
  };
  mutable std::mutex mutex_;
  std::map<std::string, Entry, std::less<>> types_;  // by type name
};

// "RIHS01_" + 64 lower-case hex digits of a hash string as rosidl_parse_type_hash_string reads it
// ("RIHS", version 01 in two hex digits, then any separator, 71 characters in all; hex digits in
// either case); nullopt when it does not parse.
std::optional<std::string> parse_type_hash(std::string_view text);

// The reply of ~/get_type_description as rcl words it: a hash that does not parse answers "Failed
// to parse type hash", one no type of the node has "Type not currently in use by this node". As
// rcl, the type is found by its hash alone (type_name is not looked at); the sources come only
// when include_type_sources is set.
msgs::GetTypeDescriptionResponse describe_node_type(const NodeTypeCache& cache,
                                                    const msgs::GetTypeDescriptionRequest& request);

}  // namespace rbsim::node
