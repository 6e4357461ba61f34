// The hosted services' calls on their own thread (src/hosted.hpp).
#include "hosted.hpp"

namespace rbsim::foxglove::detail {

namespace {

// The decoders of a service's request and response (<type>_Request, _Response), from the schemas
// its spec advertises: what a json call is converted by.
std::vector<HostedCalls::Codecs> make_codecs(const std::vector<HostedService>& services) {
  std::vector<HostedCalls::Codecs> codecs(services.size());
  for (std::size_t i = 0; i < services.size(); ++i) {
    const ServiceSpec& spec = services[i].spec;
    auto request = msgs::MessageDecoder::create(spec.type + std::string(msgs::kServiceRequestSuffix),
                                                spec.request_schema);
    auto response = msgs::MessageDecoder::create(spec.type + std::string(msgs::kServiceResponseSuffix),
                                                 spec.response_schema);
    if (!request) {
      codecs[i].problem = request.error().message;
    } else if (!response) {
      codecs[i].problem = response.error().message;
    } else {
      codecs[i].request = std::move(request.value());
      codecs[i].response = std::move(response.value());
    }
  }
  return codecs;
}

}  // namespace

HostedCalls::HostedCalls(const std::vector<HostedService>& services, ServiceId first_id, Answer answer)
    : services_(services),
      first_id_(first_id),
      answer_(std::move(answer)),
      codecs_(make_codecs(services)),
      thread_([this] { serve(); }) {}

HostedCalls::~HostedCalls() {
  stop();
}

void HostedCalls::call(std::uint64_t connection, ServiceCall call) {
  {
    const std::lock_guard lock(mu_);
    pending_.push_back({connection, std::move(call)});
  }
  wake_.notify_one();
}

Result<std::string> HostedCalls::request_cdr(const ServiceCall& call) const {
  if (call.encoding != "json") return call.payload;
  const Codecs& codecs = codecs_[call.service - first_id_];
  const std::string& name = services_[call.service - first_id_].spec.name;
  if (!codecs.request) return Error{name + " takes no json request (its schema: " + codecs.problem + ")"};
  Bytes cdr;
  if (Status st = codecs.request->from_json(call.payload, cdr); !st)
    return Error{name + ": json request: " + st.error().message};
  return std::string(reinterpret_cast<const char*>(cdr.data()), cdr.size());
}

Result<std::string> HostedCalls::reply_in(const ServiceCall& call, std::string cdr) const {
  if (call.encoding != "json") return cdr;
  std::string json;
  if (Status st = codecs_[call.service - first_id_].response->to_json(
          {reinterpret_cast<const std::byte*>(cdr.data()), cdr.size()}, json);
      !st)
    return Error{services_[call.service - first_id_].spec.name +
                 ": its reply as json: " + st.error().message};
  return json;
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
    Result<std::string> response = request_cdr(call);
    if (response) response = services_[call.service - first_id_].call(response.value());
    if (response) response = reply_in(call, std::move(response.value()));
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
