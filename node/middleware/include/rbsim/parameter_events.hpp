// /parameter_events as rclcpp makes it, for its publisher (the node's services) and its readers
// (the bridge's RemoteSteering): rcl_interfaces/msg/ParameterEvent, reliable, volatile, keep last 1000.
#pragma once

#include <string>

#include "rbsim/interfaces.hpp"
#include "rbsim/middleware.hpp"

namespace rbsim::node {

inline RawTopic parameter_events_topic() {
  return RawTopic{"/parameter_events", std::string(msgs::ParameterEvent::kType)};
}

inline QosSpec parameter_events_qos() {
  QosSpec q;
  q.transient_local = false;
  q.keep_all = false;
  q.depth = 1000;
  return q;
}

}  // namespace rbsim::node
