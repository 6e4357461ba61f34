// The node: a Sink that publishes every topic of a step over DDS (rbsim node), and the Pacer that
// releases the steps at wall-clock time before any sink publishes them.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "rbsim/middleware.hpp"
#include "rbsim/sink.hpp"

namespace rbsim::node {

struct NodeOptions {
  std::uint32_t domain = kDomainFromEnvironment;  // ROS_DOMAIN_ID, else 0 (create_dds_participant)
  std::string ns = "rbsim";
  double rate = 1.0;               // real-time factor (Pacer); 0: as fast as possible
  std::int64_t publish_every = 1;  // publish every k-th step; create() refuses < 1
  std::int32_t keep_last = 0;      // per-step writers keep last N instead of keep all (0)
  msgs::TopicSet topics = msgs::default_topics();
  // Shared with the other sinks of a run (the Foxglove sink), so each step is encoded once; when
  // null the sink encodes for itself.
  std::shared_ptr<msgs::StepMessages> messages;
  // Ctrl-C: a write blocked on a subscriber that stopped reading (or died: it stays matched until
  // its lease expires) gives up on its sample once this turns true, and finish() waits about a
  // second for acknowledgements instead of 30 s.
  bool (*stop)() = nullptr;
};
// Publishes the selected latched topics (scene description, markers: transient local) at begin()
// and the selected per-step topics on every k-th step.
class DdsSink final : public Sink {
 public:
  static Result<std::unique_ptr<DdsSink>> create(const Participant& participant, const NodeOptions& options);
  Status begin(const Scene& scene, const World& world) override;
  Status write(const World& world) override;
  // Waits (bounded) until subscribers acknowledged everything, so nothing in flight is lost
  // when the node exits.
  Status finish() override;
  // Bodies came or went (a spawn or delete at this boundary): the latched scene description and
  // markers of the world as it now is, then its current step's per-step topics at once, so a
  // paused run shows the change without stepping (as a state set does).
  bool follows_structure() const override { return true; }
  Status restructure(const World& world, const Entities& entities) override;
  // A reset applied (the controller's observer, on the run loop's thread, the world at step 0 by
  // then): publishes /clock at once, so subscribers see time jump back to 0 while the run stays
  // paused (the other topics follow with the next step). Nothing before begin().
  void time_reset();
  // Waits until `count` subscriptions match the first selected per-step topic (body states by
  // default); false when `stop` turned true.
  bool wait_for_subscribers(std::int32_t count, bool (*stop)());
  std::uint64_t published() const { return published_; }
  // A live change (a control command, between steps); values < 1 are taken as 1.
  void set_publish_every(std::int64_t every) { options_.publish_every = every < 1 ? 1 : every; }

 private:
  DdsSink() = default;
  Status publish(msgs::TopicId id, const World& world);
  NodeOptions options_;
  std::vector<std::optional<Publisher>> publishers_;  // by TopicId; empty when not selected
  std::vector<msgs::TopicId> ids_;                    // the selected topics, latched first
  std::shared_ptr<msgs::StepMessages> messages_;
  std::uint64_t published_ = 0;
  const World* world_ = nullptr;  // the run's world (begin()), for time_reset()
};

// Paces a run to wall time: published step n (every k-th) is computed and released at start +
// (n - n0) dt / rate, with n0 and start taken at begin() (so each --loop pass starts afresh). The
// wait comes before the step's boundary (DriverOptions::pace calls wait()), not after computing
// it: a command that arrives while the run waits applies at that boundary and shows in the very
// step released next, one step sooner than a wait between computing and publishing would allow.
// A sink only for begin() and rebase().
class Pacer final : public Sink {
 public:
  Pacer(double rate, std::int64_t publish_every)
      : rate_(rate), every_(publish_every < 1 ? 1 : publish_every) {}
  Status begin(const Scene& scene, const World& world) override;
  Status write(const World&) override { return Ok{}; }
  Status finish() override { return Ok{}; }
  // Before the boundary of the step after `world`'s: waits until that step is due (when it is
  // one that is published).
  void wait(const World& world) const;
  // When the step after `world`'s is due (monotonic clock, ns), or nothing when it goes at once
  // (rate 0) or is not published. wait() sleeps until this time.
  std::optional<std::int64_t> due_ns(const World& world) const;
  // A live change of pace (a control command, between steps). The Driver then calls rebase(),
  // from which the new pace counts.
  void set_pace(double rate, std::int64_t publish_every) {
    rate_ = rate;
    every_ = publish_every < 1 ? 1 : publish_every;
  }
  // After a pause, a reset or a change of pace: the next step is due now, the ones after it
  // counted from there (no burst to catch up the time spent paused).
  void rebase(const World& world) override;
  // Pacing does not depend on the bodies: it follows any change.
  bool follows_structure() const override { return true; }
  Status restructure(const World&, const Entities&) override { return Ok{}; }

 private:
  double rate_;
  std::int64_t every_;
  std::int64_t start_ns_ = 0;  // monotonic clock at begin()
  std::int64_t start_step_ = 0;
};

}  // namespace rbsim::node
