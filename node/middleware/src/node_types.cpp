// The node type cache and ~/get_type_description's answers (rbsim/node_types.hpp).
#include "rbsim/node_types.hpp"

#include "rbsim/type_hash.hpp"

namespace rbsim::node {

TypeRegistration::TypeRegistration(std::shared_ptr<NodeTypeCache> cache, std::string type)
    : cache_(std::move(cache)), type_(std::move(type)) {}

TypeRegistration& TypeRegistration::operator=(TypeRegistration&& other) noexcept {
  if (this != &other) {
    if (cache_) cache_->unregister(type_);
    cache_ = std::move(other.cache_);
    type_ = std::move(other.type_);
  }
  return *this;
}

TypeRegistration::~TypeRegistration() {
  if (cache_) cache_->unregister(type_);
}

TypeRegistration NodeTypeCache::register_type(const std::shared_ptr<NodeTypeCache>& cache,
                                              std::string_view type) {
  if (!cache) return {};
  // The hash is computed once per process (msgs::type_hash caches it), outside the lock.
  Result<std::string> hash = msgs::type_hash(type);
  if (!hash) return {};
  const std::lock_guard lock(cache->mutex_);
  auto it = cache->types_.find(type);
  if (it == cache->types_.end()) it = cache->types_.emplace(std::string(type), Entry{hash.value(), 0}).first;
  ++it->second.registrations;
  return TypeRegistration(cache, std::string(type));
}

void NodeTypeCache::unregister(const std::string& type) {
  const std::lock_guard lock(mutex_);
  const auto it = types_.find(type);
  if (it != types_.end() && --it->second.registrations == 0) types_.erase(it);
}

std::vector<std::string> NodeTypeCache::types() const {
  const std::lock_guard lock(mutex_);
  std::vector<std::string> out;
  for (const auto& [name, entry] : types_) out.push_back(name);
  return out;
}

std::optional<std::string> NodeTypeCache::find(std::string_view hash) const {
  const std::lock_guard lock(mutex_);
  for (const auto& [name, entry] : types_) {
    if (entry.hash == hash) return name;
  }
  return std::nullopt;
}

std::optional<std::string> parse_type_hash(std::string_view text) {
  constexpr std::size_t kLength = 71;  // "RIHS01_" + 32 bytes in hex
  const auto nibble = [](char c) -> int {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
  };
  // rosidl_parse_type_hash_string reads a C string: it ends at the first NUL.
  text = text.substr(0, text.find('\0'));
  if (text.size() < 7 || !text.starts_with("RIHS")) return std::nullopt;
  if (nibble(text[4]) != 0 || nibble(text[5]) != 1 || text.size() != kLength) return std::nullopt;
  std::string out = "RIHS01_";
  for (const char c : text.substr(7)) {
    const int n = nibble(c);
    if (n < 0) return std::nullopt;
    out += "0123456789abcdef"[n];
  }
  return out;
}

msgs::GetTypeDescriptionResponse describe_node_type(const NodeTypeCache& cache,
                                                    const msgs::GetTypeDescriptionRequest& request) {
  msgs::GetTypeDescriptionResponse res;
  const std::optional<std::string> hash = parse_type_hash(request.type_hash);
  if (!hash) {
    res.failure_reason = "Failed to parse type hash";
    return res;
  }
  const std::optional<std::string> type = cache.find(*hash);
  if (!type) {
    res.failure_reason = "Type not currently in use by this node";
    return res;
  }
  Result<msgs::TypeDescription> description = msgs::type_description(*type);
  if (!description) {  // registered types are described: not expected
    res.failure_reason = "Failed to populate TypeDescription to response.";
    return res;
  }
  res.type_description = std::move(description.value());
  if (request.include_type_sources)
    res.type_sources = msgs::type_sources(res.type_description, msgs::shipped_definition);
  res.successful = true;
  return res;
}

}  // namespace rbsim::node
