// A run published into the Foxglove server: the channels of rbsim's topics and the sink.
#include "rbsim/foxglove.hpp"

namespace rbsim::foxglove {

Result<std::vector<ChannelSpec>> ros2_channels(const msgs::TopicSet& topics, std::string_view ns,
                                               std::vector<ChannelId>* ids) {
  std::vector<ChannelSpec> channels;
  if (ids != nullptr) ids->assign(msgs::kTopicCount, 0);
  for (const msgs::TopicSpec& spec : msgs::topics()) {
    if (!topics.test(static_cast<std::size_t>(spec.id))) continue;
    auto schema = msgs::ros2msg_schema(spec.type);
    if (!schema) return schema.error();
    ChannelSpec c;
    c.topic = msgs::topic_name(spec, ns);
    c.schema_name = std::string(spec.type);
    c.schema = std::move(schema.value());
    c.latched = spec.latched();
    channels.push_back(std::move(c));
    if (ids != nullptr) (*ids)[static_cast<std::size_t>(spec.id)] = static_cast<ChannelId>(channels.size());
  }
  return channels;
}

FoxgloveSink::FoxgloveSink(Server& server, std::vector<ChannelId> ids, const SinkOptions& options)
    : server_(&server), ids_(std::move(ids)), options_(options) {
  ids_.resize(msgs::kTopicCount, 0);
  if (options_.publish_every < 1) options_.publish_every = 1;
}

void FoxgloveSink::publish(const msgs::TopicSpec& spec, const World& world) {
  const ChannelId ch = ids_[static_cast<std::size_t>(spec.id)];
  if (ch == 0 || !options_.topics.test(static_cast<std::size_t>(spec.id))) return;
  // Nothing is encoded for a channel nobody watches; a latched one is kept for later subscribers.
  if (!spec.latched() && !server_->subscribed(ch)) return;
  server_->publish(ch, msgs::sim_time_ns(world), messages_->get(spec.id, world));
}

Status FoxgloveSink::begin(const Scene& scene, const World& world) {
  messages_ =
      options_.messages ? options_.messages : std::make_shared<msgs::StepMessages>(scene, options_.ns);
  server_->new_session();
  for (const msgs::TopicSpec& spec : msgs::topics()) {
    if (spec.latched()) publish(spec, world);
  }
  return write(world);
}

Status FoxgloveSink::write(const World& world) {
  if (world.step_index() % options_.publish_every != 0) return Ok{};
  publish_step(world);
  return Ok{};
}

void FoxgloveSink::publish_step(const World& world) {
  // The step's messages go before its time message: each publish wakes the server's thread, and
  // a time message sent first would make the first wake-up (and the client's) carry 9 bytes.
  for (const msgs::TopicSpec& spec : msgs::topics()) {
    if (spec.per_step) publish(spec, world);
  }
  server_->time(msgs::sim_time_ns(world));
}

Status FoxgloveSink::restructure(const World& world, const Entities& entities) {
  messages_->restructure(entities);
  for (const msgs::TopicSpec& spec : msgs::topics()) {
    if (spec.latched()) publish(spec, world);
  }
  publish_step(world);
  return Ok{};
}

Status FoxgloveSink::finish() {
  (void)server_->flush(2.0);  // a client that does not keep up is not waited for longer
  return Ok{};
}

}  // namespace rbsim::foxglove
