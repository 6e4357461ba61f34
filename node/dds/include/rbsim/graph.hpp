// A process's entry on the ROS 2 graph: what rmw_dds_common's graph cache holds about the local
// participant, published on "ros_discovery_info" (rmw_dds_common/msg/ParticipantEntitiesInfo) as
// rmw_cyclonedds_cpp does, so `ros2 node list` and every ROS 2 client library see rbsim's node
// with its readers and writers. The DDS backend's endpoints (publishers, subscriptions, a service's
// request reader and reply writer, when they are the node's: EndpointOptions::in_graph,
// ServiceOptions::in_graph) register here when they are created and unregister when they go; every
// change republishes the whole entry (keep last 1, transient local: a late joiner gets the
// current one).
#pragma once

#include <dds/dds.h>

#include <memory>
#include <mutex>

#include "rbsim/dds.hpp"
#include "rbsim/middleware.hpp"
#include "rbsim/ros_graph_msgs.hpp"

namespace rbsim::node {

class Graph {
 public:
  enum class Kind : std::uint8_t { Reader, Writer };
  // The ros_discovery_info writer on `participant` (not listed itself, as rmw lists neither its
  // discovery writer nor its reader), publishing the node with no endpoints yet.
  static Result<std::unique_ptr<Graph>> create(dds_entity_t participant, const NodeName& node,
                                               RosDistro distro);
  // The DDS GUID of a participant, reader or writer: what rmw_cyclonedds_cpp makes its GID of.
  static msgs::Guid guid_of(dds_entity_t entity);
  // Publishes the entry without the node, as rmw does when a node is destroyed (best effort).
  ~Graph();
  Graph(const Graph&) = delete;
  Graph& operator=(const Graph&) = delete;

  // Lists an endpoint of the node and republishes. Thread-safe. A failed publication is reported
  // but the endpoint stays listed (the next change publishes it).
  [[nodiscard]] Status add(Kind kind, const msgs::Guid& guid);
  // Unlists it (a GUID not listed changes nothing) and republishes.
  [[nodiscard]] Status remove(const msgs::Guid& guid);

  const msgs::Guid& participant_guid() const { return info_.participant; }
  RosDistro distro() const { return distro_; }
  // The entry as published last (a copy, for tests and diagnostics).
  msgs::ParticipantEntities entry() const;

 private:
  Graph(Publisher writer, msgs::ParticipantEntities info, RosDistro distro)
      : writer_(std::move(writer)), info_(std::move(info)), distro_(distro) {}
  [[nodiscard]] Status publish_locked();
  mutable std::mutex mutex_;
  Publisher writer_;
  msgs::ParticipantEntities info_;
  RosDistro distro_;
  Bytes cdr_;
};

}  // namespace rbsim::node
