// The replay's player state and its services (player.hpp).
#include "player_clock.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "rbsim/assert.hpp"
#include "rbsim/clock.hpp"
#include "rbsim/interfaces.hpp"
#include "rbsim/service.hpp"
#include "rbsim/service_set.hpp"

namespace rbsim::bag {

using namespace node;

namespace {
constexpr auto kPoll = std::chrono::milliseconds(50);  // the longest the loop waits without looking at stop
}  // namespace

std::uint64_t PlayerClock::now_log_locked() const {
  if (paused_ || rate_ <= 0.0) return anchor_log_;
  const std::int64_t elapsed = std::max<std::int64_t>(0, monotonic_ns() - anchor_wall_);
  return anchor_log_ + static_cast<std::uint64_t>(std::llround(static_cast<double>(elapsed) * rate_));
}

std::int64_t PlayerClock::due_wall_locked(std::uint64_t log_time) const {
  if (log_time <= anchor_log_) return anchor_wall_;
  return anchor_wall_ +
         static_cast<std::int64_t>(std::llround(static_cast<double>(log_time - anchor_log_) / rate_));
}

void PlayerClock::pause() {
  const std::lock_guard lock(mutex_);
  if (paused_) return;
  anchor_log_ = now_log_locked();
  paused_ = true;
  loop_wake_.notify_all();
}

void PlayerClock::resume() {
  const std::lock_guard lock(mutex_);
  if (!paused_) return;
  anchor_wall_ = monotonic_ns();  // the clock goes on from where it stood
  paused_ = false;
  loop_wake_.notify_all();
}

bool PlayerClock::toggle_paused() {
  if (paused()) {
    resume();
    return false;
  }
  pause();
  return true;
}

bool PlayerClock::paused() const {
  const std::lock_guard lock(mutex_);
  return paused_;
}

double PlayerClock::rate() const {
  const std::lock_guard lock(mutex_);
  return rate_;
}

bool PlayerClock::set_rate(double rate) {
  if (!(rate > 0.0) || !std::isfinite(rate)) return false;
  const std::lock_guard lock(mutex_);
  anchor_log_ = now_log_locked();
  anchor_wall_ = monotonic_ns();
  rate_ = rate;
  loop_wake_.notify_all();
  return true;
}

bool PlayerClock::seek(std::uint64_t sim_ns, double timeout_s) {
  std::unique_lock lock(mutex_);
  if (closed_) return false;
  seek_request_ = sim_ns;
  const std::uint64_t serial = ++seek_serial_;
  loop_wake_.notify_all();
  answer_.wait_for(lock, std::chrono::duration<double>(timeout_s),
                   [&] { return seek_answered_ >= serial || closed_; });
  if (seek_answered_ < serial) {
    if (seek_request_ && seek_serial_ == serial) seek_request_.reset();  // withdrawn: never taken
    return false;
  }
  return seek_answer_;
}

std::uint64_t PlayerClock::burst(std::uint64_t count, double timeout_s) {
  std::unique_lock lock(mutex_);
  if (!paused_ || closed_) return 0;
  burst_left_ = count == 0 ? std::numeric_limits<std::uint64_t>::max() : count;
  burst_done_ = 0;
  burst_active_ = true;
  loop_wake_.notify_all();
  if (!answer_.wait_for(lock, std::chrono::duration<double>(timeout_s),
                        [&] { return !burst_active_ || closed_; })) {
    burst_active_ = false;  // what was not published by now is not wanted any more
    burst_left_ = 0;
  }
  return burst_done_;
}

PlayerStatus PlayerClock::status() const {
  const std::lock_guard lock(mutex_);
  PlayerStatus s;
  s.log_time = now_log_locked();
  s.sim_time = sim_ns_;
  s.rate = rate_;
  s.paused = paused_;
  return s;
}

void PlayerClock::check_locked() const {
  RBSIM_ASSERT(rate_ >= 0.0, "the player's rate is 0 (as fast as possible) or positive");
  RBSIM_ASSERT(seek_answered_ <= seek_serial_, "no seek is answered before it is asked");
  RBSIM_ASSERT(burst_active_ || burst_left_ == 0, "messages are wanted only by an active burst");
  RBSIM_ASSERT(!closed_ || (!burst_active_ && !seek_request_), "a closed player holds no request");
}

PlayerClock::Next PlayerClock::wait_due(std::uint64_t log_time, bool (*stop)()) {
  std::unique_lock lock(mutex_);
  while (true) {
    check_locked();
    if (stop()) return Next::Stop;
    if (seek_request_) return Next::Seek;
    if (paused_) {
      if (burst_active_ && burst_left_ > 0) return Next::Publish;
      loop_wake_.wait_for(lock, kPoll);
      continue;
    }
    if (rate_ <= 0.0) return Next::Publish;
    const std::int64_t now = monotonic_ns();
    const std::int64_t due = due_wall_locked(log_time);
    if (now >= due) return Next::Publish;
    loop_wake_.wait_for(lock, std::min<std::chrono::nanoseconds>(std::chrono::nanoseconds(due - now), kPoll));
  }
}

void PlayerClock::published(std::uint64_t log_time, std::optional<std::uint64_t> sim_ns) {
  const std::lock_guard lock(mutex_);
  check_locked();
  if (sim_ns) sim_ns_ = sim_ns;
  if (paused_ && burst_active_ && burst_left_ > 0) {
    anchor_log_ = std::max(anchor_log_, log_time);  // the paused clock stands at what was stepped to
    ++burst_done_;
    if (--burst_left_ == 0) {
      burst_active_ = false;
      answer_.notify_all();
    }
  } else if (rate_ <= 0.0) {
    anchor_log_ = log_time;
    anchor_wall_ = monotonic_ns();
  }
}

std::optional<std::uint64_t> PlayerClock::take_seek() {
  const std::lock_guard lock(mutex_);
  std::optional<std::uint64_t> s = seek_request_;
  seek_request_.reset();
  return s;
}

void PlayerClock::seek_done(bool moved, std::uint64_t log_time) {
  const std::lock_guard lock(mutex_);
  if (moved) {
    anchor_log_ = log_time;
    anchor_wall_ = monotonic_ns();
  }
  seek_answered_ = seek_serial_;
  seek_answer_ = moved;
  check_locked();
  answer_.notify_all();
}

void PlayerClock::jump(std::uint64_t log_time) {
  const std::lock_guard lock(mutex_);
  anchor_log_ = log_time;
  anchor_wall_ = monotonic_ns();
}

void PlayerClock::pass_end() {
  const std::lock_guard lock(mutex_);
  if (burst_active_) {
    burst_active_ = false;
    burst_left_ = 0;
  }
  if (seek_request_) {
    seek_request_.reset();
    seek_answered_ = seek_serial_;
    seek_answer_ = false;
  }
  answer_.notify_all();
}

void PlayerClock::close() {
  const std::lock_guard lock(mutex_);
  closed_ = true;
  burst_active_ = false;
  burst_left_ = 0;
  seek_request_.reset();
  answer_.notify_all();
}

std::vector<PlayerService> player_services(PlayerClock& control, double wait_s) {
  using namespace msgs;
  std::vector<PlayerService> out;
  // A malformed request to a service whose response has no field to say so gets no reply.
  auto add = [&](std::string_view name, std::string_view type, ServiceServer::Handler h) {
    out.push_back({std::string(name), std::string(type), std::move(h)});
  };
  add("pause", PauseRequest::kService,
      typed_handler<PauseRequest, PauseResponse>(
          [&control](const RequestHeader&, const PauseRequest&) {
            control.pause();
            return PauseResponse{};
          },
          [](const Error&) { return std::optional<PauseResponse>(); }));
  add("resume", ResumeRequest::kService,
      typed_handler<ResumeRequest, ResumeResponse>(
          [&control](const RequestHeader&, const ResumeRequest&) {
            control.resume();
            return ResumeResponse{};
          },
          [](const Error&) { return std::optional<ResumeResponse>(); }));
  add("toggle_paused", TogglePausedRequest::kService,
      typed_handler<TogglePausedRequest, TogglePausedResponse>(
          [&control](const RequestHeader&, const TogglePausedRequest&) {
            (void)control.toggle_paused();
            return TogglePausedResponse{};
          },
          [](const Error&) { return std::optional<TogglePausedResponse>(); }));
  add("is_paused", IsPausedRequest::kService,
      typed_handler<IsPausedRequest, IsPausedResponse>(
          [&control](const RequestHeader&, const IsPausedRequest&) {
            return IsPausedResponse{control.paused()};
          },
          [](const Error&) { return std::optional<IsPausedResponse>(); }));
  add("get_rate", GetRateRequest::kService,
      typed_handler<GetRateRequest, GetRateResponse>(
          [&control](const RequestHeader&, const GetRateRequest&) { return GetRateResponse{control.rate()}; },
          [](const Error&) { return std::optional<GetRateResponse>(); }));
  add("set_rate", SetRateRequest::kService,
      typed_handler<SetRateRequest, SetRateResponse>(
          [&control](const RequestHeader&, const SetRateRequest& req) {
            return SetRateResponse{control.set_rate(req.rate)};
          },
          [](const Error&) { return std::optional<SetRateResponse>(SetRateResponse{false}); }));
  add("seek", SeekRequest::kService,
      typed_handler<SeekRequest, SeekResponse>(
          [&control, wait_s](const RequestHeader&, const SeekRequest& req) {
            const std::uint64_t sim_ns =
                req.time.sec < 0
                    ? 0
                    : static_cast<std::uint64_t>(req.time.sec) * 1'000'000'000ull + req.time.nanosec;
            return SeekResponse{control.seek(sim_ns, wait_s)};
          },
          [](const Error&) { return std::optional<SeekResponse>(SeekResponse{false}); }));
  add("play_next", PlayNextRequest::kService,
      typed_handler<PlayNextRequest, PlayNextResponse>(
          [&control, wait_s](const RequestHeader&, const PlayNextRequest&) {
            return PlayNextResponse{control.burst(1, wait_s) == 1};
          },
          [](const Error&) { return std::optional<PlayNextResponse>(PlayNextResponse{false}); }));
  add("burst", BurstRequest::kService,
      typed_handler<BurstRequest, BurstResponse>(
          [&control, wait_s](const RequestHeader&, const BurstRequest& req) {
            return BurstResponse{control.burst(req.num_messages, wait_s)};
          },
          [](const Error&) { return std::optional<BurstResponse>(BurstResponse{0}); }));
  return out;
}

Status add_player_services(ServiceSet& set, const Participant& participant, const std::string& node_name,
                           PlayerClock& control, double wait_s) {
  for (PlayerService& s : player_services(control, wait_s)) {
    if (Status st = set.add(participant, node_name, s.name, s.type, std::move(s.handler)); !st) return st;
  }
  return Ok{};
}

}  // namespace rbsim::bag
