// ros_discovery_info and /rosout messages (rbsim/ros_graph_msgs.hpp).
#include "rbsim/ros_graph_msgs.hpp"

#include "cdr.hpp"
#include "rbsim/assert.hpp"

namespace rbsim::msgs {

namespace {
// rmw_dds_common/msg/Gid: a fixed char array, so no length prefix.
void gid(detail::CdrWriter& w, const Guid& guid, std::size_t size) {
  for (std::size_t i = 0; i < size; ++i) w.u8(i < guid.size() ? guid[i] : 0);
}
}  // namespace

void encode_participant_entities(const ParticipantEntities& info, std::size_t gid_size, Bytes& out) {
  RBSIM_ASSERT(gid_size >= sizeof(Guid), "a GID holds at least the GUID");
  detail::CdrWriter w(out);
  gid(w, info.participant, gid_size);
  w.sequence_length(info.nodes.size());
  for (const NodeEntities& node : info.nodes) {
    w.string(node.ns);
    w.string(node.name);
    w.sequence_length(node.readers.size());
    for (const Guid& g : node.readers) gid(w, g, gid_size);
    w.sequence_length(node.writers.size());
    for (const Guid& g : node.writers) gid(w, g, gid_size);
  }
}

void encode_log(const LogMessage& log, Bytes& out) {
  detail::CdrWriter w(out);
  w.time(log.stamp);
  w.u8(static_cast<std::uint8_t>(log.level));
  w.string(log.name);
  w.string(log.msg);
  w.string(log.file);
  w.string(log.function);
  w.u32(log.line);
}

}  // namespace rbsim::msgs
