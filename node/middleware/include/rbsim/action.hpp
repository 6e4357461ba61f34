// ROS 2 actions over the middleware seam, as rcl_action serves them over rmw_cyclonedds_cpp: an
// action <name> of type "pkg/action/X" is three services, <name>/_action/send_goal (X_SendGoal),
// cancel_goal (action_msgs/srv/CancelGoal) and get_result (X_GetResult), and two topics,
// <name>/_action/feedback (X_FeedbackMessage; reliable, volatile, keep last 10) and
// <name>/_action/status (action_msgs/msg/GoalStatusArray; reliable, transient local, keep last 1:
// rcl_action_qos_profile_status_default). One ActionServer is the whole protocol for any action;
// what an action does is its Handlers and its executor's calls (a second action costs a table entry
// of handlers, not a second server).
//
// Goals follow rcl_action's state machine: ACCEPTED, EXECUTING, CANCELING, then SUCCEEDED, CANCELED
// or ABORTED; every change publishes the status array of every goal held. A finished goal's result
// is kept for result_timeout_s (rcl_action's 15 minutes) and answered to every get_result, at once
// or, for an active goal, when it ends (a deferred reply). A get_result for a goal the server does
// not hold is answered at once with status UNKNOWN, as rcl_action does.
//
// Untrusted clients: a request that does not decode is dropped and counted; a goal id already held
// is rejected; goals past max_goals are rejected (the oldest finished goals make room first);
// get_result waiters past max_result_waiters are answered at once with the goal's current status
// and an empty result; a client that vanished costs its reply only (the service layer counts it).
// Nothing a client sends can block the server's thread or grow its memory without bound.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <string_view>

#include "rbsim/bytes.hpp"
#include "rbsim/interfaces.hpp"
#include "rbsim/middleware.hpp"
#include "rbsim/service.hpp"
#include "rbsim/status.hpp"

namespace rbsim::node {

using msgs::GoalUuid;

struct ActionServerOptions {
  std::size_t max_goals = 64;            // goals held: active, or finished with their result kept
  double result_timeout_s = 900.0;       // how long a finished goal's result is kept (rcl_action's)
  std::size_t max_result_waiters = 256;  // get_result requests waiting for active goals, in all
  bool in_graph = true;                  // the node's endpoints (on the graph, with type hashes)
};

// What the server did (from any thread). goals = accepted + rejected; the services' own counters
// (dropped, malformed, client gone) are in the three ServiceStats.
struct ActionStats {
  std::uint64_t goals = 0, accepted = 0, rejected = 0;
  std::uint64_t rejected_duplicate = 0;  // of rejected: a goal id already held
  std::uint64_t rejected_full = 0;       // of rejected: max_goals active goals
  std::uint64_t malformed = 0;           // requests that did not decode: no reply
  std::uint64_t cancels = 0;             // cancel requests answered
  std::uint64_t canceling = 0;           // goals a cancel moved to CANCELING
  std::uint64_t results = 0;             // get_result replies written (at once or deferred)
  std::uint64_t results_unknown = 0;     // of results: for a goal not held (status UNKNOWN)
  std::uint64_t waiters_refused = 0;     // of results: answered early, max_result_waiters reached
  std::uint64_t expired = 0;             // finished goals dropped (result_timeout_s, or room)
  std::uint64_t feedback = 0;            // feedback messages published
  std::uint64_t feedback_unknown = 0;    // feedback for a goal not active: not published
  std::uint64_t status = 0;              // status arrays published
  ServiceStats send_goal, cancel_goal, get_result;
};

class ActionServer {
 public:
  // What makes it one action: all run on the server's thread and must not block.
  struct Handlers {
    // A goal request (the X_SendGoal request's CDR, goal id first): true accepts it. An accepted
    // goal is the executor's from then on: it reports feedback() and ends the goal with finish().
    std::function<bool(const GoalUuid& id, std::span<const std::byte> request)> goal;
    // A cancel of an active goal: true moves it to CANCELING (the executor still ends it with
    // finish(), CANCELED when it stopped short).
    std::function<bool(const GoalUuid& id)> cancel;
    // The X_GetResult response CDR with `status` and the action's empty result, for a goal the
    // server does not hold (UNKNOWN) or one whose waiters are full (its current status).
    std::function<void(std::int8_t status, Bytes& out)> empty_result;
  };

  // `action` is the fully qualified ROS name ("/rbsim/simulate_steps"), `action_type`
  // "pkg/action/X". Starts the server's thread.
  static Result<std::unique_ptr<ActionServer>> create(const Participant& participant, std::string_view action,
                                                      std::string_view action_type, Handlers handlers,
                                                      const ActionServerOptions& options = {});
  ~ActionServer();  // stops the thread; goals still active are left as they are (the node ends)
  ActionServer(const ActionServer&) = delete;
  ActionServer& operator=(const ActionServer&) = delete;

  // ---- Any thread; never blocks (the server's thread publishes and answers).
  // ACCEPTED -> EXECUTING (a goal canceled meanwhile stays CANCELING).
  void executing(const GoalUuid& id);
  // Publishes an X_FeedbackMessage (its CDR, goal id first) of an active goal.
  void feedback(Bytes feedback_message);
  // Ends an active goal: `status` is SUCCEEDED, CANCELED or ABORTED, `result_response` the
  // X_GetResult response CDR with that status, answered to every get_result of the goal.
  void finish(const GoalUuid& id, std::int8_t status, Bytes result_response);
  ActionStats stats() const;
  const std::string& name() const;

 private:
  struct Impl;
  explicit ActionServer(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace rbsim::node
