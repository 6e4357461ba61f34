// The hosted services' calls on their own thread (src/hosted.hpp).
#include "hosted.hpp"

namespace rbsim::foxglove::detail {

HostedCalls::HostedCalls(const std::vector<HostedService>& services, ServiceId first_id, Answer answer)
    : services_(services), first_id_(first_id), answer_(std::move(answer)), thread_([this] { serve(); }) {}

HostedCalls::~HostedCalls() {
  stop();
}

void HostedCalls::call(std::uint64_t connection, ServiceCall call) {
  if (call.encoding != "cdr") {
    answer_(connection,
            service_call_failure_json(
                call.service, call.call,
                services_[call.service - first_id_].spec.name + " takes its request in cdr only"),
            false);
    return;
  }
  {
    const std::lock_guard lock(mu_);
    pending_.push_back({connection, std::move(call)});
  }
  wake_.notify_one();
}

void HostedCalls::stop() {
  {
    const std::lock_guard lock(mu_);
    stop_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void HostedCalls::serve() {
  for (;;) {
    Pending next;
    {
      std::unique_lock lock(mu_);
      wake_.wait(lock, [this] { return stop_ || !pending_.empty(); });
      if (stop_) return;
      next = std::move(pending_.front());
      pending_.pop_front();
    }
    const ServiceCall& call = next.call;
    const Result<std::string> response = services_[call.service - first_id_].call(call.payload);
    if (!response) {
      answer_(next.connection, service_call_failure_json(call.service, call.call, response.error().message),
              false);
      continue;
    }
    std::string frame;
    append_service_call_response(
        frame, call.service, call.call, call.encoding,
        {reinterpret_cast<const std::byte*>(response.value().data()), response.value().size()});
    answer_(next.connection, std::move(frame), true);
  }
}

}  // namespace rbsim::foxglove::detail
