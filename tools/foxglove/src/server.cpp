// The Foxglove server: clients, their queues and the pump that feeds the transport.
//
// Threads: the producer (simulation, replay or DDS relay) calls publish()/time()/new_session(),
// which copy into client queues under `mu` and wake the I/O thread; everything else (handshake,
// client frames, sending, stall detection) runs on the I/O thread. The producer never waits on a
// socket, nor on websocketpp: the I/O thread holds `mu` only to take frames out of the queues
// (moves, no copies) and hands them to websocketpp after releasing it.
//
// Steering: the I/O thread reads the steering (the node's controller, or a bridge's relay to a
// node) and submits commands without holding `mu` (a closed controller answers inside submit());
// the answers and the parameter updates come from its callbacks on its own thread, through a
// ReplyLink that the server empties when it stops, so a callback after the server is gone does
// nothing.
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <mutex>
#include <thread>

#include <unordered_map>
#include <unordered_set>

#include "access.hpp"
#include "hosted.hpp"
#include "parameter_requests.hpp"
#include "rbsim/foxglove.hpp"
#include "rbsim/time.hpp"
#include "services.hpp"
#include "transport.hpp"

namespace rbsim::foxglove {

namespace {
constexpr int kTickMs = 10;  // the pump also runs this often: the stall check, websocketpp's drain
}  // namespace

struct Client {
  detail::ConnectionId connection = 0;
  ClientProtocol protocol;
  ClientQueue queue;
  std::size_t in_flight = 0;          // websocketpp's buffered amount after the last pump
  std::int64_t last_progress_ns = 0;  // when the client last read something (or had nothing to read)
  bool dropping = false;              // disconnected for not reading; waiting for the close
  // Frames taken from the queue under `mu` and sent without it (I/O thread). Their buffers go back
  // to the queue's pool at the next take, or to websocketpp when sent.
  std::vector<ClientQueue::Frame> outgoing;
  std::size_t taken = 0;
  // Steering.
  // The parameters whose updates it subscribed to (names of the table: bounded by its size).
  std::unordered_set<std::string> parameter_updates;
  std::uint32_t pending = 0;  // commands submitted, not answered
  bool backlog_told = false;  // told its requests are refused for its backlog
  Client(detail::ConnectionId id, std::uint32_t channels, bool parameters, std::uint32_t services,
         const QueueLimits& limits)
      : connection(id), protocol(channels, parameters, services), queue(limits) {}
};

struct Reply {
  std::string data;
  bool binary = false;
};

// The steering's parameter names, read at start and at every new session (a bridge's node may
// come, go or change its scene); requests check names against the table of their time.
struct ParameterTable {
  std::vector<std::string> names;  // in the steering's order
  std::unordered_map<std::string, std::size_t> index;
  explicit ParameterTable(std::vector<std::string> n) : names(std::move(n)) {
    for (std::size_t i = 0; i < names.size(); ++i) index.emplace(names[i], i);
  }
};

// How the steering's callbacks reach the server: empty once the server stops.
struct ReplyLink {
  std::mutex mu;
  Server::Impl* server = nullptr;
  // Queues `replies` for connection `id` (gone: dropped); `answered`: one of its commands is done.
  void deliver(detail::ConnectionId id, const std::vector<Reply>& replies, bool answered);
  // The steering's observer: parameterValues to each client subscribed to a changed parameter.
  void changed(const std::vector<msgs::Parameter>& parameters);
};

struct Server::Impl {
  ServerOptions options;
  std::vector<ChannelSpec> channels;
  std::unique_ptr<detail::Transport> transport;
  std::string advertise;  // the same for every client

  mutable std::mutex mu;  // guards everything below
  std::vector<std::unique_ptr<Client>> clients;
  std::string server_info;
  std::uint64_t sessions = 0;
  struct Latched {
    bool has = false;
    std::uint64_t log_time = 0;
    std::vector<std::byte> payload;
  };
  std::vector<Latched> latched;  // by channel - 1
  // The session's last time message (kNoTime: none yet): a client that connects gets it after the
  // advertisements, so it knows where a paused stream stands before its first latched message.
  // Atomic (sequentially consistent) with client_count: time() skips the lock without clients.
  static constexpr std::uint64_t kNoTime = std::numeric_limits<std::uint64_t>::max();
  std::atomic<std::uint64_t> last_time{kNoTime};
  ServerStats totals;  // of closed clients, plus the counters kept here
  std::atomic<std::size_t> client_count{0};
  std::unique_ptr<std::atomic<std::uint32_t>[]> subscribers;  // by channel - 1

  // I/O thread scratch, reused.
  ClientProtocol::Outcome outcome;

  // Steering (options.steering set): fixed for the server's life but the table (under `mu`).
  // services: the steering's (1..control_services), then options.hosted_services.
  std::vector<ServiceSpec> services;
  std::size_t control_services = 0;
  std::string advertise_services;
  std::string command_in;  // <node>/command_in, the clientPublish topic
  std::shared_ptr<const ParameterTable> table = std::make_shared<ParameterTable>(std::vector<std::string>{});
  std::shared_ptr<ReplyLink> link = std::make_shared<ReplyLink>();

  std::shared_ptr<const ParameterTable> parameters() const {
    const std::lock_guard lock(mu);
    return table;
  }
  // Reads the steering's table (without `mu`: the steering has locks of its own).
  void refresh_parameters() {
    if (options.steering == nullptr) return;
    auto fresh = std::make_shared<const ParameterTable>(options.steering->names());
    const std::lock_guard lock(mu);
    table = std::move(fresh);
  }

  Client* find(detail::ConnectionId id) {
    for (auto& c : clients) {
      if (c->connection == id) return c.get();
    }
    return nullptr;
  }

  void new_session_locked() {
    ++sessions;
    const std::int64_t ms = wall_ns() / 1'000'000;
    server_info = server_info_json(options.name, std::to_string(ms) + "-" + std::to_string(sessions),
                                   options.steering != nullptr, !services.empty());
    for (Latched& l : latched) l.has = false;
    last_time = kNoTime;
  }

  void opened(detail::ConnectionId id) {
    {
      std::lock_guard lock(mu);
      auto c = std::make_unique<Client>(id, static_cast<std::uint32_t>(channels.size()),
                                        options.steering != nullptr,
                                        static_cast<std::uint32_t>(services.size()), options.queue);
      if (options.steering != nullptr) c->protocol.accept_publish(command_in);
      c->queue.push_text(server_info);
      c->queue.push_text(advertise);
      if (!services.empty()) c->queue.push_text(advertise_services);
      if (const std::uint64_t t = last_time; t != kNoTime) c->queue.push_time(t);
      c->last_progress_ns = monotonic_ns();
      ++totals.clients;
      clients.push_back(std::move(c));
      client_count = clients.size();
    }
    pump_all();
  }

  void closed(detail::ConnectionId id) {
    std::lock_guard lock(mu);
    for (auto it = clients.begin(); it != clients.end(); ++it) {
      Client& c = **it;
      if (c.connection != id) continue;
      for (ChannelId ch = 1; ch <= channels.size(); ++ch) {
        if (c.protocol.subscription(ch)) --subscribers[ch - 1];
      }
      totals.dropped += c.queue.dropped();
      totals.warnings += c.queue.warnings();
      clients.erase(it);
      break;
    }
    client_count = clients.size();
  }

  void message(detail::ConnectionId id, const std::string& payload, bool binary) {
    std::optional<ParameterRequest> parameters;
    std::optional<ServiceCall> call;
    std::optional<ClientMessage> published;
    {
      std::lock_guard lock(mu);
      if (!handle(id, payload, binary)) return;
      parameters = std::move(outcome.parameters);
      call = std::move(outcome.call);
      published = std::move(outcome.published);
    }
    // Without `mu`: the steering may answer inside submit(), through the link.
    if (parameters) serve_parameters(id, std::move(*parameters));
    if (call) serve_call(id, std::move(*call));
    if (published) serve_publish(id, std::move(*published));
    pump_all();
  }

  // Under `mu`: whether `c` may make a request now (false: refused, and told so once per backlog).
  bool admit(Client& c, bool command, const ServiceCall* call, const char* op = "setParameters") {
    const std::size_t backlog = c.queue.kept_bytes();
    if (backlog < options.max_reply_backlog_bytes / 2) c.backlog_told = false;
    if (backlog >= options.max_reply_backlog_bytes) {
      ++totals.refused_requests;
      if (!c.backlog_told) {
        c.backlog_told = true;
        c.queue.push_text(
            status_json(StatusLevel::Error, "rbsim: requests refused until this client reads its replies (" +
                                                std::to_string(backlog) + " bytes waiting)"));
      }
      return false;
    }
    if (command && c.pending >= options.max_pending_commands) {
      ++totals.refused_requests;
      const std::string m = "too many requests in flight (" + std::to_string(options.max_pending_commands) +
                            " per client): wait for their answers";
      c.queue.push_text(call ? service_call_failure_json(call->service, call->call, m)
                             : status_json(StatusLevel::Error, op + (": " + m)));
      return false;
    }
    ++totals.requests;
    if (command) ++c.pending;
    return true;
  }

  bool handle(detail::ConnectionId id, const std::string& payload, bool binary) {
    Client* c = find(id);
    if (c == nullptr) return false;
    if (binary) {
      c->protocol.handle_binary(payload, outcome);
    } else {
      c->protocol.handle_text(payload, outcome);
    }
    for (const auto& s : outcome.unsubscribed) {
      --subscribers[s.channel - 1];
      c->queue.remove_subscription(s.id);
    }
    for (const auto& s : outcome.subscribed) {
      ++subscribers[s.channel - 1];
      const Latched& l = latched[s.channel - 1];
      if (l.has) c->queue.push_message(ClientQueue::Kind::Latched, s.id, l.log_time, l.payload);
    }
    for (const std::string& r : outcome.replies) c->queue.push_text(r);
    if (outcome.parameters && !admit(*c, outcome.parameters->op == ParameterRequest::Op::Set, nullptr)) {
      outcome.parameters.reset();
    }
    if (outcome.call && !admit(*c, true, &*outcome.call)) outcome.call.reset();
    if (outcome.published && !admit(*c, true, nullptr, "clientPublish")) outcome.published.reset();
    return true;
  }

  void reply(detail::ConnectionId id, const std::vector<Reply>& replies, bool answered) {
    link->deliver(id, replies, answered);
  }

  std::unique_ptr<detail::HostedCalls> hosted;  // options.hosted_services' calls, after the steering's

  // I/O thread, without `mu`.
  void serve_parameters(detail::ConnectionId id, ParameterRequest r);
  void serve_call(detail::ConnectionId id, ServiceCall call);
  void serve_publish(detail::ConnectionId id, ClientMessage message);

  // Under `mu`: takes the frames websocketpp may have now (while less than max_in_flight_bytes is
  // buffered there) and notes whether the client read anything since the last pump.
  void take(Client& c, std::int64_t now) {
    c.taken = 0;
    if (c.dropping) return;
    std::size_t buffered = transport->buffered(c.connection);
    if (buffered == 0 || buffered < c.in_flight) c.last_progress_ns = now;
    while (!c.queue.empty()) {
      const std::size_t next = c.queue.front_size();
      if (buffered > 0 && buffered + next > options.max_in_flight_bytes) break;
      if (c.taken == c.outgoing.size()) c.outgoing.emplace_back();
      c.queue.pop(c.outgoing[c.taken++]);
      buffered += next;
    }
  }

  // Under `mu`: records what websocketpp holds and disconnects a client that has read nothing for
  // stall_timeout_s.
  void settle(Client& c, std::int64_t now) {
    if (c.dropping) return;
    const std::size_t buffered = transport->buffered(c.connection);
    c.in_flight = buffered;
    const bool waiting = buffered > 0 || !c.queue.empty();
    if (waiting && now - c.last_progress_ns > seconds_to_ns_clamped(options.stall_timeout_s)) {
      c.dropping = true;
      ++totals.disconnected;
      transport->drop(c.connection);
    }
  }

  // I/O thread. Only it adds or removes clients, so the Client objects stay valid between the
  // locked phases.
  void pump_all() {
    const std::int64_t now = monotonic_ns();
    {
      std::lock_guard lock(mu);
      for (auto& c : clients) take(*c, now);
    }
    for (auto& c : clients) {
      for (std::size_t i = 0; i < c->taken; ++i) {
        ClientQueue::Frame& f = c->outgoing[i];
        if (!transport->send(c->connection, f.data, f.binary)) break;
      }
    }
    std::lock_guard lock(mu);
    for (auto& c : clients) settle(*c, now);
  }
};

// ---------------------------------------------------------------------------------------------
// Steering

void ReplyLink::deliver(detail::ConnectionId id, const std::vector<Reply>& replies, bool answered) {
  const std::lock_guard link_lock(mu);
  if (server == nullptr) return;
  {
    const std::lock_guard lock(server->mu);
    Client* c = server->find(id);
    if (c == nullptr) return;
    if (answered && c->pending > 0) --c->pending;
    for (const Reply& r : replies) c->queue.push_control(r.data, r.binary);
  }
  server->transport->wake();
}

void ReplyLink::changed(const std::vector<msgs::Parameter>& parameters) {
  if (parameters.empty()) return;
  const std::lock_guard link_lock(mu);
  if (server == nullptr) return;
  bool queued = false;
  {
    const std::lock_guard lock(server->mu);
    std::vector<msgs::Parameter> subset;
    for (auto& c : server->clients) {
      if (c->parameter_updates.empty()) continue;
      subset.clear();
      for (const msgs::Parameter& p : parameters) {
        if (c->parameter_updates.count(p.name) != 0) subset.push_back(p);
      }
      if (subset.empty()) continue;
      c->queue.push_text(parameter_values_json(subset));
      queued = true;
    }
  }
  if (queued) server->transport->wake();
}

namespace {
// A set's values to the steering as one command, answered through the link once applied: the
// values now, and each refusal (those found before, in `problems`, then the steering's).
void submit_set(control::Steering& steering, const std::shared_ptr<ReplyLink>& reply_link,
                detail::ConnectionId id, ParameterRequest r, std::vector<msgs::Parameter> known,
                std::vector<std::string> problems) {
  control::Command command;
  command.kind = control::CommandKind::SetParameters;
  command.atomic = false;  // each its own result, as set_parameters
  command.parameters = r.values;
  command.source = "foxglove";
  steering.submit(std::move(command),
                  [link = reply_link, id, answer = r.id, values = r.values, known = std::move(known),
                   refused = std::move(problems)](const control::CommandResult& result) mutable {
                    std::vector<Reply> out;
                    if (result.results.size() != values.size()) {
                      refused.push_back(result.message);  // never applied (the run ended)
                    } else {
                      for (std::size_t k = 0; k < values.size(); ++k) {
                        if (!result.results[k].successful) refused.push_back(result.results[k].reason);
                      }
                    }
                    if (answer) {
                      for (msgs::Parameter& p : known) {
                        for (const msgs::Parameter& c : result.changed) {
                          if (c.name == p.name) p.value = c.value;
                        }
                      }
                      out.push_back({parameter_values_json(known, answer), false});
                    }
                    if (std::string m = problems_status_json("setParameters", refused); !m.empty())
                      out.push_back({std::move(m), false});
                    link->deliver(id, out, true);
                  });
}
}  // namespace

void Server::Impl::serve_parameters(detail::ConnectionId id, ParameterRequest r) {
  using Op = ParameterRequest::Op;
  control::Steering& steering = *options.steering;
  const std::shared_ptr<const ParameterTable> table_now = parameters();
  const std::vector<std::string>& parameter_names = table_now->names;
  const std::unordered_map<std::string, std::size_t>& parameter_index = table_now->index;
  const char* op = r.op == Op::Get         ? "getParameters"
                   : r.op == Op::Set       ? "setParameters"
                   : r.op == Op::Subscribe ? "subscribeParameterUpdates"
                                           : "unsubscribeParameterUpdates";
  std::vector<Reply> replies;
  std::vector<std::string> problems;
  if (r.op == Op::Set) {
    // Checked here, not on the run loop: a name the node does not have, and a request naming more
    // parameters than the node has (it repeats names; the run loop's work stays bounded).
    if (r.values.size() > parameter_names.size()) {
      reply(id,
            {{status_json(StatusLevel::Error, "setParameters: " + std::to_string(r.values.size()) +
                                                  " values in one request, more than the node's " +
                                                  std::to_string(parameter_names.size()) + " parameters"),
              false}},
            true);
      return;
    }
    detail::keep_known_names(r, parameter_index, problems);
  } else if (r.names.empty()) {
    r.names = parameter_names;  // every parameter
  }
  // The values now: a get's answer, and a set's answer for what it does not change.
  std::vector<std::optional<msgs::ParameterValue>> now = steering.get(r.names);
  std::vector<msgs::Parameter> known;
  for (std::size_t k = 0; k < r.names.size(); ++k) {
    if (now[k]) {
      known.push_back({r.names[k], *now[k]});
    } else if (r.op != Op::Set) {
      problems.push_back("no parameter '" + r.names[k].substr(0, 200) + "'");
    }
  }
  if (r.op == Op::Get) {
    replies.push_back({parameter_values_json(known, r.id), false});
  } else if (r.op == Op::Subscribe || r.op == Op::Unsubscribe) {
    const std::lock_guard lock(mu);
    if (Client* c = find(id)) {
      for (const msgs::Parameter& p : known) {
        if (r.op == Op::Subscribe) {
          c->parameter_updates.insert(p.name);
        } else {
          c->parameter_updates.erase(p.name);
        }
      }
    }
  }
  if (r.op != Op::Set) {
    if (std::string m = problems_status_json(op, problems); !m.empty())
      replies.push_back({std::move(m), false});
    reply(id, replies, false);
    return;
  }
  detail::type_untyped_integers(r, steering.types(r.names));
  submit_set(steering, link, id, std::move(r), std::move(known), std::move(problems));
}

void Server::Impl::serve_call(detail::ConnectionId id, ServiceCall call) {
  if (call.service > control_services) {
    hosted->call(id, std::move(call));
    return;
  }
  const control::ControlService& service = control::control_services()[call.service - 1];
  Result<control::Command> command = detail::decode_request(service, call.encoding, call.payload);
  if (!command) {
    reply(id, {{service_call_failure_json(call.service, call.call, command.error().message), false}}, true);
    return;
  }
  command->source = "foxglove";
  options.steering->submit(std::move(command.value()), [link = link, id, call = std::move(call)](
                                                           const control::CommandResult& result) {
    const control::ControlService& s = control::control_services()[call.service - 1];
    const std::string payload = detail::encode_response(s, call.encoding, result);
    Reply r{{}, true};
    append_service_call_response(r.data, call.service, call.call, call.encoding,
                                 {reinterpret_cast<const std::byte*>(payload.data()), payload.size()});
    link->deliver(id, {r}, true);
  });
}

// A command on <node>/command_in: applied at the next boundary, source "foxglove"; its refusal
// (undecodable, or what the run loop said) comes back as a status error, success says nothing.
// Parameter names are checked on this thread, as for setParameters (decode_command).
void Server::Impl::serve_publish(detail::ConnectionId id, ClientMessage message) {
  const std::string where = "clientPublish " + command_in + ": ";
  Result<control::Command> command =
      detail::decode_command(message.encoding, message.payload, parameters()->index);
  if (!command) {
    reply(id, {{status_json(StatusLevel::Error, where + command.error().message), false}}, true);
    return;
  }
  command->step = control::Command::kNextStep;
  command->source = "foxglove";
  const std::string kind = control::to_string(command->kind);
  options.steering->submit(std::move(command.value()), [link = link, id, what = where + kind + ": "](
                                                           const control::CommandResult& result) {
    std::vector<std::string> refused;
    if (!result.successful) refused.push_back(result.message);
    for (const auto& r : result.results) {
      if (!r.successful && refused.empty()) refused.push_back(r.reason);
    }
    std::vector<Reply> out;
    if (!refused.empty()) out.push_back({status_json(StatusLevel::Error, what + refused.front()), false});
    link->deliver(id, out, true);
  });
}

Result<std::unique_ptr<Server>> Server::start(const ServerOptions& options,
                                              std::vector<ChannelSpec> channels) {
  if (options.token.empty() && !options.allow_insecure && !is_loopback(options.address)) {
    return Error{"refusing to serve " + websocket_url(options.address, options.port) +
                     " beyond this host without a token (or allow_insecure)",
                 ErrorCode::InvalidArgument};
  }
  if (!options.token.empty()) {
    if (const std::string problem = token_problem(options.token); !problem.empty())
      return Error{problem, ErrorCode::InvalidArgument};
  }
  std::unique_ptr<Server> s(new Server());
  s->impl_ = std::make_unique<Impl>();
  Impl& im = *s->impl_;
  im.options = options;
  im.channels = std::move(channels);
  im.advertise = advertise_json(im.channels);
  im.latched.resize(im.channels.size());
  if (options.steering != nullptr) {
    im.services = detail::control_service_specs(options.node);
    im.control_services = im.services.size();
    im.command_in = options.node + "/" + std::string(kCommandInSuffix);
    im.refresh_parameters();
  }
  for (const HostedService& h : options.hosted_services) im.services.push_back(h.spec);
  if (!im.services.empty()) im.advertise_services = advertise_services_json(im.services);
  im.subscribers = std::make_unique<std::atomic<std::uint32_t>[]>(im.channels.size());
  for (std::size_t i = 0; i < im.channels.size(); ++i) im.subscribers[i] = 0;
  im.new_session_locked();
  const bool tls = !options.tls_cert.empty();
  im.transport = detail::Transport::create(tls);
  detail::TransportHandlers h;
  h.choose_subprotocol = [](const std::vector<std::string>& offered) {
    const auto chosen = choose_subprotocol(offered);
    return chosen ? std::string(*chosen) : std::string();
  };
  Impl* p = &im;
  h.on_open = [p](detail::ConnectionId id) { p->opened(id); };
  h.on_close = [p](detail::ConnectionId id) { p->closed(id); };
  h.on_message = [p](detail::ConnectionId id, const std::string& payload, bool binary) {
    p->message(id, payload, binary);
  };
  h.on_pump = [p] { p->pump_all(); };
  h.on_refused = [p] {
    std::lock_guard lock(p->mu);
    ++p->totals.refused;
  };
  h.admit = detail::admission(options, [p](detail::AccessGate::Verdict v) {
    std::lock_guard lock(p->mu);
    ++(v == detail::AccessGate::Verdict::Unauthorized  ? p->totals.unauthorized
       : v == detail::AccessGate::Verdict::RateLimited ? p->totals.rate_limited
                                                       : p->totals.full);
  });
  h.on_handshake_timeout = [p] {
    std::lock_guard lock(p->mu);
    ++p->totals.handshake_timeouts;
  };
  const std::string err = im.transport->listen(
      {options.address, options.port, kMaxReadFrame, kTickMs,
       static_cast<int>(std::lround(options.handshake_timeout_s * 1000)), options.tls_cert, options.tls_key},
      std::move(h));
  if (!err.empty()) {
    return Error{"cannot listen on " + websocket_url(options.address, options.port, tls) + ": " + err};
  }
  if (options.steering != nullptr || !options.hosted_services.empty()) im.link->server = &im;
  if (!options.hosted_services.empty()) {
    im.hosted = std::make_unique<detail::HostedCalls>(
        im.options.hosted_services, static_cast<ServiceId>(im.control_services + 1),
        [link = im.link](std::uint64_t id, std::string frame, bool binary) {
          link->deliver(id, {Reply{std::move(frame), binary}}, true);
        });
  }
  if (options.steering != nullptr) {
    options.steering->on_command([link = im.link](const control::Command&, const control::CommandResult& r) {
      link->changed(r.changed);
    });
  }
  im.transport->run();
  return s;
}

Server::~Server() {
  stop();
}

void Server::stop() {
  if (!impl_) return;
  {
    const std::lock_guard lock(impl_->link->mu);  // the steering's callbacks do nothing from here
    impl_->link->server = nullptr;
  }
  if (impl_->hosted) impl_->hosted->stop();
  if (impl_->transport) impl_->transport->stop();
}

std::uint16_t Server::port() const {
  return impl_->transport->port();
}

const std::vector<ChannelSpec>& Server::channels() const {
  return impl_->channels;
}

void Server::new_session() {
  Impl& im = *impl_;
  im.refresh_parameters();
  {
    std::lock_guard lock(im.mu);
    im.new_session_locked();
    for (auto& c : im.clients) c->queue.push_text(im.server_info);
  }
  im.transport->wake();
}

bool Server::subscribed(ChannelId channel) const {
  if (channel == 0 || channel > impl_->channels.size()) return false;
  return impl_->subscribers[channel - 1].load(std::memory_order_relaxed) > 0;
}

void Server::publish(ChannelId channel, std::uint64_t log_time_ns, std::span<const std::byte> payload) {
  Impl& im = *impl_;
  if (channel == 0 || channel > im.channels.size()) return;
  const bool latched = im.channels[channel - 1].latched;
  if (!latched && !subscribed(channel)) return;
  bool queued = false;
  {
    std::lock_guard lock(im.mu);
    if (latched) {
      Impl::Latched& l = im.latched[channel - 1];
      l.has = true;
      l.log_time = log_time_ns;
      l.payload.assign(payload.begin(), payload.end());  // reuses its capacity
    }
    for (auto& c : im.clients) {
      if (const auto sub = c->protocol.subscription(channel)) {
        c->queue.push_message(latched ? ClientQueue::Kind::Latched : ClientQueue::Kind::PerStep, *sub,
                              log_time_ns, payload);
        queued = true;
      }
    }
    if (queued) ++im.totals.published;
  }
  if (queued) im.transport->wake();
}

void Server::time(std::uint64_t time_ns) {
  Impl& im = *impl_;
  im.last_time = time_ns;
  if (im.client_count == 0) return;
  {
    std::lock_guard lock(im.mu);
    for (auto& c : im.clients) c->queue.push_time(time_ns);
  }
  im.transport->wake();
}

std::size_t Server::client_count() const {
  return impl_->client_count.load();
}

bool Server::flush(double timeout_s) {
  Impl& im = *impl_;
  const std::int64_t deadline = monotonic_ns() + seconds_to_ns_clamped(timeout_s);
  while (true) {
    bool pending = false;
    {
      std::lock_guard lock(im.mu);
      for (const auto& c : im.clients)
        pending = pending || (!c->dropping && (!c->queue.empty() || c->in_flight > 0));
    }
    if (!pending) return true;
    if (monotonic_ns() >= deadline) return false;
    im.transport->wake();
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

ServerStats Server::stats() const {
  std::lock_guard lock(impl_->mu);
  ServerStats s = impl_->totals;
  for (const auto& c : impl_->clients) {
    s.dropped += c->queue.dropped();
    s.warnings += c->queue.warnings();
  }
  return s;
}

}  // namespace rbsim::foxglove
