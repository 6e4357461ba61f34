// The node's output: every topic of a step published over DDS, paced to wall time.
#include <algorithm>
#include <cmath>
#include <string>

#include "rbsim/clock.hpp"
#include "rbsim/dds_sink.hpp"

namespace rbsim::node {

Result<std::unique_ptr<DdsSink>> DdsSink::create(const Participant& participant, const NodeOptions& options) {
  if (options.publish_every < 1) {
    return Error{"publish every " + std::to_string(options.publish_every) + " steps: must be at least 1"};
  }
  if (options.topics.none()) return Error{"no topics to publish"};
  std::unique_ptr<DdsSink> sink(new DdsSink());
  sink->options_ = options;
  sink->publishers_.resize(msgs::kTopicCount);
  sink->ids_ = msgs::topic_ids(options.topics);
  for (const msgs::TopicId id : sink->ids_) {
    const msgs::TopicSpec& spec = msgs::topic(id);
    auto pub = Publisher::create(participant, spec, msgs::topic_name(spec, options.ns),
                                 qos_for(spec, options.keep_last));
    if (!pub) return pub.error();
    sink->publishers_[static_cast<std::size_t>(spec.id)].emplace(std::move(pub.value()));
  }
  return sink;
}

Status DdsSink::publish(msgs::TopicId id, const World& world) {
  Status st = publishers_[static_cast<std::size_t>(id)]->publish(messages_->get(id, world), options_.stop);
  if (st) ++published_;
  if (st.code() == ErrorCode::Cancelled) return Ok{};  // stopping: the run loop ends after this step
  return st;
}

Status DdsSink::begin(const Scene& scene, const World& world) {
  world_ = &world;
  messages_ =
      options_.messages ? options_.messages : std::make_shared<msgs::StepMessages>(scene, options_.ns);
  for (const msgs::TopicId id : ids_) {
    if (msgs::topic(id).per_step) continue;
    if (Status st = publish(id, world); !st) return st;
  }
  return write(world);
}

Status DdsSink::write(const World& world) {
  if (world.step_index() % options_.publish_every != 0) return Ok{};
  for (const msgs::TopicId id : ids_) {
    if (!msgs::topic(id).per_step) continue;
    if (Status st = publish(id, world); !st) return st;
  }
  return Ok{};
}

Status DdsSink::restructure(const World& world, const Entities& entities) {
  messages_->restructure(entities);
  for (const msgs::TopicId id : ids_) {  // latched first
    if (Status st = publish(id, world); !st) return st;
  }
  return Ok{};
}

void DdsSink::time_reset() {
  if (world_ == nullptr || !publishers_[static_cast<std::size_t>(msgs::TopicId::Clock)]) return;
  // A failed write is the next step's to report (an observer has no status).
  (void)publish(msgs::TopicId::Clock, *world_);
}

Status DdsSink::finish() {
  for (auto& p : publishers_) {
    if (!p) continue;
    Status st = p->flush(30.0, options_.stop);
    // Stopped by the user: what a dead or stalled subscriber did not acknowledge is not an error.
    if (!st && !(options_.stop != nullptr && options_.stop())) return st;
  }
  return Ok{};
}

bool DdsSink::wait_for_subscribers(std::int32_t count, bool (*stop)()) {
  const auto per_step =
      std::find_if(ids_.begin(), ids_.end(), [](msgs::TopicId id) { return msgs::topic(id).per_step; });
  const auto& watched =
      publishers_[static_cast<std::size_t>(per_step != ids_.end() ? *per_step : ids_.front())];
  return watched->wait_for_subscribers(count, stop);
}

Status Pacer::begin(const Scene&, const World& world) {
  start_ns_ = monotonic_ns();
  start_step_ = world.step_index();
  return Ok{};
}

void Pacer::rebase(const World& world) {
  // The step at hand went out before the pause (or is the reset's step 0): the next one is due now.
  start_ns_ = monotonic_ns();
  start_step_ = world.step_index() + 1;
}

std::optional<std::int64_t> Pacer::due_ns(const World& world) const {
  const std::int64_t next = world.step_index() + 1;
  if (rate_ <= 0.0 || next % every_ != 0) return std::nullopt;
  // (steps since the start) * dt of simulated time take that / rate of wall time.
  const double due = static_cast<double>(next - start_step_) * world.dt() / rate_;
  return start_ns_ + seconds_to_ns_clamped(due);
}

void Pacer::wait(const World& world) const {
  if (const std::optional<std::int64_t> due = due_ns(world)) sleep_until(*due);
}

}  // namespace rbsim::node
