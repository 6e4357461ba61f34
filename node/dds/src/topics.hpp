#pragma once
#include <dds/dds.h>

#include <string_view>

#include "rbsim/msgs.hpp"

namespace rbsim::node {
// idlc's topic descriptor of each topic's type.
const dds_topic_descriptor_t* descriptor(msgs::TopicId id);
// node/config/cyclonedds-loopback.xml, compiled in (generated source).
extern const std::string_view kLoopbackConfig;
}  // namespace rbsim::node
