#include "topics.hpp"

#include "geometry_msgs/msg/PoseArray.h"
#include "rbsim_msgs/msg/BodyStates.h"
#include "rbsim_msgs/msg/Command.h"
#include "rbsim_msgs/msg/EnergyTerms.h"
#include "rbsim_msgs/msg/SceneDescription.h"
#include "rbsim_msgs/msg/SpringStates.h"
#include "rosgraph_msgs/msg/Clock.h"
#include "tf2_msgs/msg/TFMessage.h"
#include "visualization_msgs/msg/Marker.h"
#include "visualization_msgs/msg/MarkerArray.h"

namespace rbsim::node {
const dds_topic_descriptor_t* descriptor(msgs::TopicId id) {
  switch (id) {
    case msgs::TopicId::SceneDescription:
      return &rbsim_msgs_msg_dds__SceneDescription__desc;
    case msgs::TopicId::BodyStates:
      return &rbsim_msgs_msg_dds__BodyStates__desc;
    case msgs::TopicId::SpringStates:
      return &rbsim_msgs_msg_dds__SpringStates__desc;
    case msgs::TopicId::Energy:
      return &rbsim_msgs_msg_dds__EnergyTerms__desc;
    case msgs::TopicId::Poses:
      return &geometry_msgs_msg_dds__PoseArray__desc;
    case msgs::TopicId::Markers:
      return &visualization_msgs_msg_dds__MarkerArray__desc;
    case msgs::TopicId::Tf:
      return &tf2_msgs_msg_dds__TFMessage__desc;
    case msgs::TopicId::Springs:
      return &visualization_msgs_msg_dds__Marker__desc;
    case msgs::TopicId::Clock:
      return &rosgraph_msgs_msg_dds__Clock__desc;
    case msgs::TopicId::Commands:
      return &rbsim_msgs_msg_dds__Command__desc;
  }
  return nullptr;
}
}  // namespace rbsim::node
