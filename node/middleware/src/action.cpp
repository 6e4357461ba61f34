// The action server (action.hpp): three services and two topics served on one thread of its own.
#include "rbsim/action.hpp"

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <mutex>
#include <optional>
#include <thread>
#include <utility>
#include <vector>

#include "rbsim/assert.hpp"
#include "rbsim/time.hpp"

namespace rbsim::node {

namespace {

using Clock = std::chrono::steady_clock;
using msgs::GoalStatus;

constexpr std::size_t kBudget = 16;  // requests of one service handled before the next one's turn

bool terminal(std::int8_t s) {
  return s == GoalStatus::kSucceeded || s == GoalStatus::kCanceled || s == GoalStatus::kAborted;
}
bool zero(const GoalUuid& id) {
  return std::all_of(id.begin(), id.end(), [](std::uint8_t b) { return b == 0; });
}
bool zero(const msgs::Time& t) {
  return t.sec == 0 && t.nanosec == 0;
}
bool at_or_before(const msgs::Time& a, const msgs::Time& b) {
  return a.sec < b.sec || (a.sec == b.sec && a.nanosec <= b.nanosec);
}
// Goal stamps are wall time, as rcl_action's with the node's clock not on simulated time.
msgs::Time wall_now() {
  return msgs::time_from_ns(static_cast<std::uint64_t>(wall_ns()));
}

// The status topic: late joiners get the last array (rcl_action_qos_profile_status_default).
QosSpec status_qos() {
  QosSpec q;
  q.transient_local = true;
  q.depth = 1;
  return q;
}
QosSpec feedback_qos() {
  QosSpec q;
  q.depth = 10;  // rmw_qos_profile_default
  return q;
}

}  // namespace

struct ActionServer::Impl {
  struct Goal {
    msgs::GoalInfo info;
    std::int8_t status = GoalStatus::kAccepted;
    Bytes result;                        // the GetResult response, once terminal
    std::vector<RequestHeader> waiters;  // get_result requests waiting for the end
    Clock::time_point finished{};
  };
  // What executor threads hand the server's thread (under mutex).
  struct Posted {
    enum class Kind : std::uint8_t { Executing, Feedback, Finish } kind;
    GoalUuid id{};
    std::int8_t status = 0;
    Bytes bytes;
  };

  std::string name;
  Handlers handlers;
  ActionServerOptions options;
  std::optional<ServiceServer> send_goal, cancel_goal, get_result;
  std::optional<Publisher> feedback_pub, status_pub;

  mutable std::mutex mutex;  // guards posted, wake, stopping and stats
  std::condition_variable wake;
  bool woken = false, stopping = false;
  std::vector<Posted> posted;
  ActionStats counts;
  std::thread thread;

  // The server's thread only.
  std::vector<Goal> goals;  // in acceptance order
  std::size_t waiting = 0;  // get_result waiters over all goals
  bool status_dirty = false;
  Bytes buffer;

  void count(std::uint64_t ActionStats::*field, std::uint64_t n = 1) {
    const std::lock_guard lock(mutex);
    counts.*field += n;
  }
  void notify() {
    {
      const std::lock_guard lock(mutex);
      woken = true;
    }
    wake.notify_one();
  }
  Goal* find(const GoalUuid& id) {
    const auto it =
        std::find_if(goals.begin(), goals.end(), [&](const Goal& g) { return g.info.goal_id == id; });
    return it == goals.end() ? nullptr : &*it;
  }

  void loop();
  void apply_posted();
  void expire();
  bool make_room();
  bool on_send_goal(const RequestHeader& header, std::span<const std::byte> request, Bytes& reply);
  bool on_cancel(std::span<const std::byte> request, Bytes& reply);
  bool on_get_result(const RequestHeader& header, std::span<const std::byte> request, Bytes& reply);
  void publish_status();
};

// The thread: woken by any service's arrival or an executor's post, or every 20 ms (the services
// retry replies waiting for their client's reader; results expire).
void ActionServer::Impl::loop() {
  const ServiceServer::Handler goal_handler = [this](const RequestHeader& h, std::span<const std::byte> r,
                                                     Bytes& out) { return on_send_goal(h, r, out); };
  const ServiceServer::Handler cancel_handler = [this](const RequestHeader&, std::span<const std::byte> r,
                                                       Bytes& out) { return on_cancel(r, out); };
  const ServiceServer::Handler result_handler = [this](const RequestHeader& h, std::span<const std::byte> r,
                                                       Bytes& out) { return on_get_result(h, r, out); };
  while (true) {
    {
      std::unique_lock lock(mutex);
      wake.wait_for(lock, std::chrono::milliseconds(20), [this] { return woken || stopping; });
      if (stopping) return;
      woken = false;
    }
    // Posts first, so a result finished before a get_result arrived is answered at once.
    apply_posted();
    send_goal->serve(goal_handler, kBudget);
    cancel_goal->serve(cancel_handler, kBudget);
    get_result->serve(result_handler, kBudget);
    expire();
    if (status_dirty) publish_status();
  }
}

void ActionServer::Impl::apply_posted() {
  std::vector<Posted> now;
  {
    const std::lock_guard lock(mutex);
    now.swap(posted);
  }
  for (Posted& p : now) {
    Goal* g = find(p.id);
    switch (p.kind) {
      case Posted::Kind::Executing:
        if (g != nullptr && g->status == GoalStatus::kAccepted) {
          g->status = GoalStatus::kExecuting;
          status_dirty = true;
        }
        break;
      case Posted::Kind::Feedback:
        if (g == nullptr || terminal(g->status)) {
          count(&ActionStats::feedback_unknown);
          break;
        }
        if (feedback_pub->publish(p.bytes)) count(&ActionStats::feedback);
        break;
      case Posted::Kind::Finish:
        RBSIM_ASSERT(terminal(p.status), "an action goal ends SUCCEEDED, CANCELED or ABORTED");
        if (g == nullptr || terminal(g->status)) break;  // ended twice: the first end stands
        g->status = p.status;
        g->result = std::move(p.bytes);
        g->finished = Clock::now();
        for (const RequestHeader& h : g->waiters) {
          get_result->reply(h, g->result);
          count(&ActionStats::results);
        }
        waiting -= g->waiters.size();
        g->waiters.clear();
        status_dirty = true;
        break;
    }
  }
}

// Finished goals whose result is older than result_timeout_s go (rcl_action's expiry).
void ActionServer::Impl::expire() {
  const auto now = Clock::now();
  const auto keep = std::chrono::duration<double>(options.result_timeout_s);
  const std::size_t before = goals.size();
  std::erase_if(goals, [&](const Goal& g) { return terminal(g.status) && now - g.finished >= keep; });
  if (goals.size() != before) {
    count(&ActionStats::expired, before - goals.size());
    status_dirty = true;
  }
}

// Room for one more goal: the oldest finished goal goes when max_goals are held; false when every
// held goal is active.
bool ActionServer::Impl::make_room() {
  if (goals.size() < options.max_goals) return true;
  const auto oldest =
      std::find_if(goals.begin(), goals.end(), [](const Goal& g) { return terminal(g.status); });
  if (oldest == goals.end()) return false;
  goals.erase(oldest);
  count(&ActionStats::expired);
  status_dirty = true;
  return true;
}

bool ActionServer::Impl::on_send_goal(const RequestHeader&, std::span<const std::byte> request,
                                      Bytes& reply) {
  const Result<GoalUuid> id = msgs::request_goal_id(request);
  if (!id) {
    count(&ActionStats::malformed);
    return false;
  }
  msgs::SendGoalResponse res;
  res.stamp = wall_now();
  if (find(*id) != nullptr) {
    count(&ActionStats::rejected_duplicate);
  } else if (!make_room()) {
    count(&ActionStats::rejected_full);
  } else {
    // The goal is held before the handler sees it, so an executor's post about it (from another
    // thread, at once) finds it.
    goals.push_back(Goal{msgs::GoalInfo{*id, res.stamp}, GoalStatus::kAccepted, {}, {}, {}});
    res.accepted = handlers.goal(*id, request);
    if (!res.accepted) goals.pop_back();
  }
  {
    const std::lock_guard lock(mutex);
    ++counts.goals;
    ++(res.accepted ? counts.accepted : counts.rejected);
  }
  if (res.accepted) status_dirty = true;
  msgs::encode(res, reply);
  return true;
}

// rcl_action_process_cancel_request's rules: which goals a request names, then each active one
// asked of the executor.
bool ActionServer::Impl::on_cancel(std::span<const std::byte> request, Bytes& reply) {
  msgs::CancelGoalRequest req;
  if (!msgs::decode(request, req)) {
    count(&ActionStats::malformed);
    return false;
  }
  const msgs::GoalInfo& want = req.goal_info;
  msgs::CancelGoalResponse res;
  const Goal* named = nullptr;
  for (Goal& g : goals) {
    const bool by_id = !zero(want.goal_id) && g.info.goal_id == want.goal_id;
    const bool by_stamp = zero(want.goal_id) ? zero(want.stamp) || at_or_before(g.info.stamp, want.stamp)
                                             : !zero(want.stamp) && at_or_before(g.info.stamp, want.stamp);
    if (by_id) named = &g;
    if (!by_id && !by_stamp) continue;
    if (terminal(g.status)) continue;
    if (g.status == GoalStatus::kCanceling || handlers.cancel(g.info.goal_id)) {
      if (g.status != GoalStatus::kCanceling) count(&ActionStats::canceling);
      g.status = GoalStatus::kCanceling;
      res.goals_canceling.push_back(g.info);
      status_dirty = true;
    }
  }
  if (!res.goals_canceling.empty()) {
    res.return_code = msgs::CancelGoalResponse::kErrorNone;
  } else if (!zero(want.goal_id) && named == nullptr) {
    res.return_code = msgs::CancelGoalResponse::kErrorUnknownGoalId;
  } else if (named != nullptr && terminal(named->status)) {
    res.return_code = msgs::CancelGoalResponse::kErrorGoalTerminated;
  } else {
    // Nothing to cancel (no goal named, or the executor refused): rcl_action answers REJECTED.
    res.return_code = msgs::CancelGoalResponse::kErrorRejected;
  }
  count(&ActionStats::cancels);
  msgs::encode(res, reply);
  return true;
}

bool ActionServer::Impl::on_get_result(const RequestHeader& header, std::span<const std::byte> request,
                                       Bytes& reply) {
  msgs::GetResultRequest req;
  if (!msgs::decode(request, req)) {
    count(&ActionStats::malformed);
    return false;
  }
  Goal* g = find(req.goal_id);
  if (g == nullptr) {
    handlers.empty_result(GoalStatus::kUnknown, reply);
    count(&ActionStats::results_unknown);
    count(&ActionStats::results);
    return true;
  }
  if (terminal(g->status)) {
    reply = g->result;
    count(&ActionStats::results);
    return true;
  }
  if (waiting >= options.max_result_waiters) {
    handlers.empty_result(g->status, reply);
    count(&ActionStats::waiters_refused);
    count(&ActionStats::results);
    return true;
  }
  g->waiters.push_back(header);
  ++waiting;
  return false;  // answered by ServiceServer::reply when the goal ends
}

void ActionServer::Impl::publish_status() {
  msgs::GoalStatusArray a;
  a.status_list.reserve(goals.size());
  for (const Goal& g : goals) a.status_list.push_back(GoalStatus{g.info, g.status});
  msgs::encode(a, buffer);
  if (status_pub->publish(buffer)) count(&ActionStats::status);
  status_dirty = false;
}

// ---------------------------------------------------------------------------------------------
ActionServer::ActionServer(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

ActionServer::~ActionServer() {
  {
    const std::lock_guard lock(impl_->mutex);
    impl_->stopping = true;
  }
  impl_->wake.notify_one();
  if (impl_->thread.joinable()) impl_->thread.join();
}

Result<std::unique_ptr<ActionServer>> ActionServer::create(const Participant& participant,
                                                           std::string_view action,
                                                           std::string_view action_type, Handlers handlers,
                                                           const ActionServerOptions& options) {
  RBSIM_ASSERT(handlers.goal && handlers.cancel && handlers.empty_result, "an action needs all its handlers");
  auto impl = std::make_unique<Impl>();
  impl->name = std::string(action);
  impl->handlers = std::move(handlers);
  impl->options = options;
  impl->options.max_goals = std::max<std::size_t>(options.max_goals, 1);
  const std::string base = impl->name + "/_action/";
  const std::string type(action_type);
  ServiceOptions so;
  so.in_graph = options.in_graph;
  so.on_arrival = [raw = impl.get()] { raw->notify(); };
  const auto server = [&](const char* name, const std::string& srv_type,
                          std::optional<ServiceServer>& out) -> Status {
    Result<ServiceServer> s = ServiceServer::create(participant, base + name, srv_type, so);
    if (!s) return with_context("action " + impl->name + ": ", s.error());
    out.emplace(std::move(s.value()));
    return Ok{};
  };
  if (Status st = server("send_goal", type + "_SendGoal", impl->send_goal); !st) return st.error();
  if (Status st = server("cancel_goal", std::string(msgs::CancelGoalRequest::kService), impl->cancel_goal);
      !st)
    return st.error();
  if (Status st = server("get_result", type + "_GetResult", impl->get_result); !st) return st.error();
  EndpointOptions eo;
  eo.in_graph = options.in_graph;
  auto feedback = Publisher::create(participant, RawTopic{base + "feedback", type + "_FeedbackMessage"},
                                    feedback_qos(), eo);
  if (!feedback) return with_context("action " + impl->name + ": ", feedback.error());
  impl->feedback_pub.emplace(std::move(feedback.value()));
  auto status = Publisher::create(
      participant, RawTopic{base + "status", std::string(msgs::GoalStatusArray::kType)}, status_qos(), eo);
  if (!status) return with_context("action " + impl->name + ": ", status.error());
  impl->status_pub.emplace(std::move(status.value()));
  Impl* raw = impl.get();
  impl->thread = std::thread([raw] { raw->loop(); });
  return std::unique_ptr<ActionServer>(new ActionServer(std::move(impl)));
}

void ActionServer::executing(const GoalUuid& id) {
  {
    const std::lock_guard lock(impl_->mutex);
    impl_->posted.push_back({Impl::Posted::Kind::Executing, id, 0, {}});
  }
  impl_->notify();
}

void ActionServer::feedback(Bytes feedback_message) {
  const Result<GoalUuid> id = msgs::request_goal_id(feedback_message);
  RBSIM_ASSERT(id.ok(), "a feedback message begins with its goal id");
  {
    const std::lock_guard lock(impl_->mutex);
    impl_->posted.push_back({Impl::Posted::Kind::Feedback, id.value(), 0, std::move(feedback_message)});
  }
  impl_->notify();
}

void ActionServer::finish(const GoalUuid& id, std::int8_t status, Bytes result_response) {
  {
    const std::lock_guard lock(impl_->mutex);
    impl_->posted.push_back({Impl::Posted::Kind::Finish, id, status, std::move(result_response)});
  }
  impl_->notify();
}

ActionStats ActionServer::stats() const {
  ActionStats s;
  {
    const std::lock_guard lock(impl_->mutex);
    s = impl_->counts;
  }
  s.send_goal = impl_->send_goal->stats();
  s.cancel_goal = impl_->cancel_goal->stats();
  s.get_result = impl_->get_result->stats();
  return s;
}

const std::string& ActionServer::name() const {
  return impl_->name;
}

}  // namespace rbsim::node
