// The local participant's ros_discovery_info entry (graph.hpp).
#include "rbsim/graph.hpp"

#include "dds_backend.hpp"

#include <algorithm>
#include <cstring>

namespace rbsim::node {

msgs::Guid Graph::guid_of(dds_entity_t entity) {
  dds_guid_t guid{};
  msgs::Guid out{};
  if (dds_get_guid(entity, &guid) == DDS_RETCODE_OK) std::memcpy(out.data(), guid.v, out.size());
  return out;
}

Result<std::unique_ptr<Graph>> Graph::create(dds_entity_t participant, const NodeName& node,
                                             RosDistro distro) {
  // rmw_cyclonedds_cpp's discovery publisher: reliable, transient local, keep last 1, and no
  // ROS topic prefix (the DDS topic is "ros_discovery_info").
  const DdsTopic topic{"ros_discovery_info", msgs::dds_type_name(msgs::kParticipantEntitiesInfoType),
                       std::string(msgs::kParticipantEntitiesInfoType), "ros_discovery_info"};
  EndpointOptions options;
  options.in_graph = false;
  auto writer =
      DdsPublisher::create(DdsContext{participant, distro, nullptr}, topic, QosSpec{true, false, 1}, options);
  if (!writer) return writer.error();
  msgs::ParticipantEntities info;
  info.participant = guid_of(participant);
  info.nodes.push_back({node.ns, node.name, {}, {}});
  std::unique_ptr<Graph> graph(
      new Graph(Publisher(std::move(writer.value()), "ros_discovery_info"), std::move(info), distro));
  std::lock_guard lock(graph->mutex_);
  if (Status st = graph->publish_locked(); !st) return st.error();
  return graph;
}

Status Graph::add(Kind kind, const msgs::Guid& guid) {
  std::lock_guard lock(mutex_);
  msgs::NodeEntities& node = info_.nodes.front();
  (kind == Kind::Reader ? node.readers : node.writers).push_back(guid);
  return publish_locked();
}

Status Graph::remove(const msgs::Guid& guid) {
  std::lock_guard lock(mutex_);
  msgs::NodeEntities& node = info_.nodes.front();
  const std::size_t before = node.readers.size() + node.writers.size();
  std::erase(node.readers, guid);
  std::erase(node.writers, guid);
  if (node.readers.size() + node.writers.size() == before) return Ok{};
  return publish_locked();
}

Graph::~Graph() {
  std::lock_guard lock(mutex_);
  info_.nodes.clear();
  // Nobody to tell of a failure in a destructor. A short, bounded wait lets the entry reach the
  // graph's readers before the participant goes (they drop it then anyway, on its disposal).
  if (publish_locked()) static_cast<void>(writer_.flush(0.5));
}

msgs::ParticipantEntities Graph::entry() const {
  std::lock_guard lock(mutex_);
  return info_;
}

Status Graph::publish_locked() {
  msgs::encode_participant_entities(info_, gid_size(distro_), cdr_);
  return writer_.publish(cdr_);
}

}  // namespace rbsim::node
