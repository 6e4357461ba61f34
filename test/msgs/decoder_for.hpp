// The schema-driven decoder of one of rbsim's topics, for the msgs tests.
#pragma once

#include <gtest/gtest.h>

#include "rbsim/msgs.hpp"

inline rbsim::msgs::MessageDecoder decoder_for(rbsim::msgs::TopicId id) {
  const auto type = rbsim::msgs::topic(id).type;
  auto schema = rbsim::msgs::ros2msg_schema(type);
  EXPECT_TRUE(schema.ok());
  auto d = rbsim::msgs::MessageDecoder::create(type, schema.value());
  EXPECT_TRUE(d.ok()) << d.error().message;
  return std::move(d.value());
}
