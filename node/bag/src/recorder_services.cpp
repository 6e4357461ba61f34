// The recorder's rosbag2 services (rbsim/recorder.hpp's RecorderServices).
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <memory>
#include <mutex>
#include <vector>

#include "rbsim/interfaces.hpp"
#include "rbsim/recorder.hpp"
#include "rbsim/rosout.hpp"
#include "rbsim/service_set.hpp"

namespace rbsim::bag {

using namespace node;

namespace {
constexpr auto kWait = std::chrono::seconds(5);  // a split or snapshot answered by then at the latest
}  // namespace

struct RecorderServices::Impl {
  Recorder& recorder;
  explicit Impl(Recorder& r) : recorder(r) {}
  // A split or snapshot asked for by a handler, carried out by the recording loop.
  struct Request {
    bool snapshot = false;
    bool done = false, ok = false;
  };
  std::mutex mutex;  // guards `requests` and every Request's done and ok
  std::condition_variable answered;
  std::vector<std::shared_ptr<Request>> requests;  // shared: a handler that gave up may be gone
  ServiceSet services;                             // last: stopped before the rest goes

  // The handler's side: queues `r` and waits (bounded) for the loop to carry it out.
  bool ask(bool snapshot) {
    auto r = std::make_shared<Request>(Request{snapshot});
    std::unique_lock lock(mutex);
    requests.push_back(r);
    const bool in_time = answered.wait_for(lock, kWait, [&r] { return r->done; });
    if (!in_time) std::erase(requests, r);  // not taken yet: never carried out
    return in_time && r->ok;
  }
};

Result<std::unique_ptr<RecorderServices>> RecorderServices::create(const Participant& participant,
                                                                   Recorder& recorder) {
  using namespace msgs;
  std::unique_ptr<RecorderServices> s(new RecorderServices());
  s->impl_ = std::make_unique<Impl>(recorder);
  Impl& im = *s->impl_;
  const std::string node = participant.node().fully_qualified();
  // A malformed request to a service whose response has no field to say so gets no reply.
  auto add = [&](std::string_view name, std::string_view type, ServiceServer::Handler h) {
    return im.services.add(participant, node, name, type, std::move(h));
  };
  Status st = add("pause", PauseRequest::kService,
                  typed_handler<PauseRequest, PauseResponse>(
                      [&recorder](const RequestHeader&, const PauseRequest&) {
                        recorder.set_paused(true);
                        return PauseResponse{};
                      },
                      [](const Error&) { return std::optional<PauseResponse>(); }));
  if (st) {
    st = add("resume", ResumeRequest::kService,
             typed_handler<ResumeRequest, ResumeResponse>(
                 [&recorder](const RequestHeader&, const ResumeRequest&) {
                   recorder.set_paused(false);
                   return ResumeResponse{};
                 },
                 [](const Error&) { return std::optional<ResumeResponse>(); }));
  }
  if (st) {
    st = add("is_paused", IsPausedRequest::kService,
             typed_handler<IsPausedRequest, IsPausedResponse>(
                 [&recorder](const RequestHeader&, const IsPausedRequest&) {
                   return IsPausedResponse{recorder.paused()};
                 },
                 [](const Error&) { return std::optional<IsPausedResponse>(); }));
  }
  if (st) {
    st = add("split_bagfile", SplitBagfileRequest::kService,
             typed_handler<SplitBagfileRequest, SplitBagfileResponse>(
                 [&im](const RequestHeader&, const SplitBagfileRequest&) {
                   (void)im.ask(false);
                   return SplitBagfileResponse{};
                 },
                 [](const Error&) { return std::optional<SplitBagfileResponse>(); }));
  }
  if (st) {
    st = add(
        "snapshot", SnapshotRequest::kService,
        typed_handler<SnapshotRequest, SnapshotResponse>(
            [&im](const RequestHeader&, const SnapshotRequest&) { return SnapshotResponse{im.ask(true)}; },
            [](const Error&) { return std::optional<SnapshotResponse>(SnapshotResponse{false}); }));
  }
  if (!st) return st.error();
  im.services.start();
  return s;
}

RecorderServices::~RecorderServices() {
  if (!impl_) return;
  impl_->services.stop();
}

Status RecorderServices::carry_out(bool quiet, bool snapshot) {
  Impl& im = *impl_;
  std::vector<std::shared_ptr<Impl::Request>> now;
  {
    const std::lock_guard lock(im.mutex);
    now.swap(im.requests);
  }
  if (snapshot) now.push_back(std::make_shared<Impl::Request>(Impl::Request{true}));
  if (now.empty()) return Ok{};
  Status failure = Ok{};
  std::vector<bool> ok;
  for (const auto& r : now) {
    // Refusals (a split of one .mcap file, a snapshot outside snapshot mode) only answer false;
    // a failure to write ends the recording, as any write failure does.
    if (r->snapshot) {
      Result<std::uint64_t> n = im.recorder.snapshot();
      ok.push_back(n.ok());
      if (!n && n.error().code != ErrorCode::InvalidArgument && failure) failure = n.error();
      if (n && !quiet) {
        RBSIM_LOG(Info, "rbsim record: snapshot: %llu messages written to %s\n",
                  static_cast<unsigned long long>(n.value()),
                  n.value() > 0 ? im.recorder.files().back().c_str() : "nothing (none kept yet)");
      }
    } else {
      const Status st = im.recorder.split_now();
      ok.push_back(st.ok());
      if (!st && st.error().code != ErrorCode::InvalidArgument && failure) failure = st;
      if (st && !quiet)
        RBSIM_LOG(Info, "rbsim record: split: now writing %s\n", im.recorder.files().back().c_str());
    }
  }
  {
    const std::lock_guard lock(im.mutex);
    for (std::size_t k = 0; k < now.size(); ++k) {
      now[k]->ok = ok[k];
      now[k]->done = true;
    }
  }
  im.answered.notify_all();
  return failure;
}

}  // namespace rbsim::bag
