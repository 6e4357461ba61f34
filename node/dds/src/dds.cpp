// The seam on Cyclone DDS (dds_backend.hpp): participants, raw-CDR publishers and subscriptions,
// wait sets.
#include <dds/dds.h>
#include <dds/ddsi/ddsi_serdata.h>
#include <dds/ddsi/ddsi_sertype.h>

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <utility>

#include "dds_backend.hpp"
#include "raw_serdata.hpp"
#include "rbsim/assert.hpp"
#include "rbsim/clock.hpp"
#include "rbsim/dds.hpp"
#include "rbsim/graph.hpp"
#include "rbsim/rosout.hpp"
#include "rbsim/security.hpp"
#include "rbsim/time.hpp"
#include "rbsim/type_hash.hpp"
#include "topics.hpp"

namespace rbsim::node {

namespace {
constexpr dds_duration_t kWriteSlice = DDS_MSECS(100);
constexpr dds_duration_t kMaxBlocked = DDS_SECS(30);

dds_qos_t* make_qos(const QosSpec& q, bool reader, const EndpointOptions& options, RosDistro distro) {
  dds_qos_t* qos = dds_create_qos();
  // A reliable writer blocks when its readers fall behind: a slow recorder throttles the node
  // instead of losing samples. Each write blocks at most kWriteSlice; Publisher::publish retries
  // up to kMaxBlocked in all, asking its stop predicate between slices, so Ctrl-C ends a node
  // whose subscriber died (still matched until its lease expires) at once.
  dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, kWriteSlice);
  dds_qset_durability(qos, q.transient_local ? DDS_DURABILITY_TRANSIENT_LOCAL : DDS_DURABILITY_VOLATILE);
  // Per-step topics keep all: with keep-last, a writer drops samples a slow reader has not yet
  // acknowledged once `depth` newer ones exist, so a recorder that falls behind loses steps;
  // keep-all makes the node wait instead (scripts/soak reports losses). A reader keeps all it is
  // sent.
  if ((!q.transient_local && reader) || q.keep_all) {
    dds_qset_history(qos, DDS_HISTORY_KEEP_ALL, 0);
  } else {
    dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, q.depth);
  }
  if (q.transient_local) {
    // Cyclone keeps for late joiners what the durability service history says (by default the
    // last 1); rmw_cyclonedds_cpp sets it to the history, so /rosout's late joiners get 1000, and
    // a transient-local keep-all writer (/<ns>/commands) gives a late joiner everything.
    dds_qset_durability_service(qos, 0, q.keep_all ? DDS_HISTORY_KEEP_ALL : DDS_HISTORY_KEEP_LAST,
                                q.keep_all ? 0 : q.depth, DDS_LENGTH_UNLIMITED, DDS_LENGTH_UNLIMITED,
                                DDS_LENGTH_UNLIMITED);
  }
  if (options.lifespan_ns > 0) dds_qset_lifespan(qos, options.lifespan_ns);
  // rmw_cyclonedds_cpp's endpoint USER_DATA: the type hash (REP 2011) where the distro has them.
  if (!options.type_hash.empty() && has_type_hashes(distro)) {
    const std::string user_data = "typehash=" + options.type_hash + ";";
    dds_qset_userdata(qos, user_data.data(), user_data.size());
  }
  return qos;
}

// A matched writer's history and durability, as rosbag2 records them from its discovery data.
void offered_by(const dds_qos_t* qos, msgs::OfferedQos& out) {
  dds_history_kind_t history{};
  std::int32_t depth = 0;
  if (qos != nullptr && dds_qget_history(qos, &history, &depth)) {
    out.keep_all = history == DDS_HISTORY_KEEP_ALL;
    out.depth = out.keep_all ? 0 : depth;
  }
  dds_durability_kind_t durability{};
  if (qos != nullptr && dds_qget_durability(qos, &durability)) {
    out.transient_local = durability != DDS_DURABILITY_VOLATILE;
  }
}

// A topic of the seam by its DDS names: "rt" before the ROS name, the type's DDS name (idlc's, for
// one of msgs::topics()).
DdsTopic dds_topic(const TopicRef& ref) {
  if (ref.spec != nullptr) {
    return {msgs::dds_topic_name(ref.ros_name), descriptor(ref.spec->id)->m_typename, ref.ros_type,
            ref.ros_name};
  }
  const std::string name = msgs::dds_topic_name(ref.ros_name);
  return {name, msgs::dds_type_name(ref.ros_type), ref.ros_type, name};
}

// The endpoint's options with the type hash of its topic's type filled in (every shipped type
// hashes: a failure is a bug in the definitions, caught by msgs's tests).
EndpointOptions with_type_hash(const EndpointOptions& options, const DdsTopic& topic) {
  EndpointOptions o = options;
  if (o.type_hash.empty() && !topic.ros_type.empty()) {
    Result<std::string> hash = msgs::type_hash(topic.ros_type);
    RBSIM_ASSERT(hash, "a shipped type hashes");
    if (hash) o.type_hash = hash.value();
  }
  return o;
}
}  // namespace

std::weak_ptr<Graph> list_endpoint(const DdsContext& context, Graph::Kind kind, dds_entity_t entity,
                                   bool in_graph) {
  if (!in_graph || !context.graph) return {};
  if (Status st = context.graph->add(kind, Graph::guid_of(entity)); !st) {
    log(LogLevel::Warn, "rbsim: warning: ros_discovery_info not updated: " + st.error().message);
  }
  return context.graph;
}
void unlist_endpoint(const std::weak_ptr<Graph>& where, dds_entity_t entity) {
  const std::shared_ptr<Graph> graph = where.lock();
  if (!graph) return;
  // A failure here has no one left to report to (a destructor); the next change republishes.
  static_cast<void>(graph->remove(Graph::guid_of(entity)));
}

std::string_view loopback_config() {
  return kLoopbackConfig;
}

Result<Participant> create_dds_participant(std::uint32_t domain, const NodeName& node) {
  const RosEnvironment env = RosEnvironment::from_process();
  auto settings = resolve_dds_settings(
      env, domain == kDomainFromEnvironment ? std::nullopt : std::optional<std::uint32_t>(domain), getpid());
  if (!settings) return settings.error();
  const DdsSettings& s = settings.value();
  for (const std::string& w : s.warnings) log(LogLevel::Warn, "rbsim: warning: " + w);
  if (s.config) {
    // dds_create_domain fails harmlessly when the domain already exists in this process.
    const dds_entity_t d = dds_create_domain(s.domain, s.config->c_str());
    if (d < 0 && d != DDS_RETCODE_PRECONDITION_NOT_MET) {
      return dds_error("cannot create DDS " + s.describe(), d);
    }
  }
  // Otherwise Cyclone configures the domain itself: from CYCLONEDDS_URI, or its defaults.
  auto security =
      resolve_security(env, node, s.domain, domain == kDomainFromEnvironment ? "ROS_DOMAIN_ID" : "--domain");
  if (!security) return security.error();
  for (const std::string& w : security->warnings) log(LogLevel::Warn, "rbsim: warning: " + w);
  // rmw_cyclonedds_cpp's participant USER_DATA: the security enclave, "/" without ROS security.
  dds_qos_t* qos = dds_create_qos();
  const std::string enclave = "enclave=" + (security->enabled ? security->enclave : std::string("/")) + ";";
  dds_qset_userdata(qos, enclave.data(), enclave.size());
  if (security->enabled) set_security_properties(qos, security.value());
  const dds_entity_t p = dds_create_participant(s.domain, qos, nullptr);
  dds_delete_qos(qos);
  if (p < 0) {
    const std::string where =
        s.from_cyclonedds_uri
            ? "domain " + std::to_string(s.domain) + " (check CYCLONEDDS_URI=" + *env.cyclonedds_uri + ")"
            : s.describe();
    return dds_error(
        "cannot create a DDS participant on " + where +
            (security->enabled ? ", " + security->describe() + " from " + security->directory : ""),
        p);
  }
  // Security asked for: every command's start line says whether it runs secured.
  auto impl = std::make_unique<DdsParticipant>(
      DdsContext{p, s.distro, nullptr}, s.domain,
      s.describe() + (security->requested ? ", " + security->describe() : ""), node);
  auto graph = Graph::create(p, node, s.distro);
  if (!graph) return with_context("cannot publish the node on ros_discovery_info: ", graph.error());
  impl->context().graph = std::move(graph.value());
  return Participant(std::move(impl));
}

DdsParticipant::~DdsParticipant() {
  context_.graph.reset();  // its writer before the participant (endpoints still alive find it gone)
  if (context_.participant > 0) dds_delete(context_.participant);
}

Result<std::unique_ptr<PublisherImpl>> DdsParticipant::create_publisher(const TopicRef& topic,
                                                                        const QosSpec& qos,
                                                                        const EndpointOptions& options) {
  auto p = DdsPublisher::create(context_, dds_topic(topic), qos, options);
  if (!p) return p.error();
  return std::unique_ptr<PublisherImpl>(std::move(p.value()));
}

Result<std::unique_ptr<SubscriptionImpl>> DdsParticipant::create_subscription(
    const TopicRef& topic, const QosSpec& qos, const EndpointOptions& options) {
  auto s = DdsSubscription::create(context_, dds_topic(topic), topic.spec, qos, options);
  if (!s) return s.error();
  return std::unique_ptr<SubscriptionImpl>(std::move(s.value()));
}

Result<std::unique_ptr<ServiceServerImpl>> DdsParticipant::create_server(std::string_view service,
                                                                         std::string_view srv_type,
                                                                         const ServiceOptions& options) {
  return make_dds_server(context_, service, srv_type, options, {});
}

Result<std::unique_ptr<ServiceClientImpl>> DdsParticipant::create_client(std::string_view service,
                                                                         std::string_view srv_type,
                                                                         const ClientOptions& options) {
  return make_dds_client(context_, service, srv_type, options, {});
}

// ---------------------------------------------------------------------------------------------
Result<std::unique_ptr<DdsPublisher>> DdsPublisher::create(const DdsContext& context, const DdsTopic& raw,
                                                           const QosSpec& q, const EndpointOptions& options) {
  const ddsi_sertype* sertype = nullptr;
  auto topic = make_raw_topic(context.participant, raw.dds_name, raw.dds_type, &sertype);
  if (!topic) return topic.error();
  dds_qos_t* qos = make_qos(q, false, with_type_hash(options, raw), context.distro);
  const dds_entity_t writer = dds_create_writer(context.participant, topic.value(), qos, nullptr);
  dds_delete_qos(qos);
  if (writer < 0) {
    dds_delete(topic.value());
    return dds_error("cannot create DDS writer for " + raw.dds_name, writer);
  }
  std::unique_ptr<DdsPublisher> p(new DdsPublisher());
  p->writer_ = writer;
  p->topic_ = topic.value();
  p->sertype_ = sertype;
  p->label_ = raw.label;
  p->graph_ = list_endpoint(context, Graph::Kind::Writer, writer, options.in_graph);
  return p;
}

DdsPublisher::~DdsPublisher() {
  if (writer_ > 0) unlist_endpoint(graph_, writer_);
  if (writer_ > 0) dds_delete(writer_);
  if (topic_ > 0) dds_delete(topic_);
}

Status DdsPublisher::publish(std::span<const std::byte> cdr, bool (*stop)()) {
  ddsi_serdata* d = make_raw_serdata(sertype_, cdr);
  dds_return_t rc = DDS_RETCODE_TIMEOUT;
  for (dds_duration_t blocked = 0; rc == DDS_RETCODE_TIMEOUT && blocked < kMaxBlocked;
       blocked += kWriteSlice) {
    if (blocked > 0 && stop != nullptr && stop()) break;  // stopping: this sample is not sent
    rc = dds_writecdr(writer_, ddsi_serdata_ref(d));      // each attempt takes one reference
  }
  ddsi_serdata_unref(d);
  if (rc == DDS_RETCODE_TIMEOUT && stop != nullptr && stop()) {
    return Error{"stopped while subscribers of " + label_ + " were not keeping up", ErrorCode::Cancelled};
  }
  if (rc < 0) return dds_error("publishing on " + label_ + " failed", rc);
  return Ok{};
}

Status DdsPublisher::flush(double timeout_s, bool (*stop)()) {
  // In slices, so a stop request (a second Ctrl-C, or the first when a subscriber died) cuts the
  // wait to kStoppingFlush.
  const auto timeout = static_cast<dds_duration_t>(seconds_to_ns_clamped(timeout_s));
  constexpr dds_duration_t kStoppingFlush = DDS_SECS(1);
  dds_return_t rc = DDS_RETCODE_TIMEOUT;
  for (dds_duration_t waited = 0; rc == DDS_RETCODE_TIMEOUT && waited < timeout; waited += kWriteSlice) {
    if (stop != nullptr && stop() && waited >= kStoppingFlush) break;
    rc = dds_wait_for_acks(writer_, std::min(kWriteSlice, timeout - waited));
  }
  if (rc < 0) return dds_error("subscribers of " + label_ + " did not acknowledge everything in time", rc);
  return Ok{};
}

std::int32_t DdsPublisher::matched() const {
  dds_publication_matched_status_t st{};
  if (dds_get_publication_matched_status(writer_, &st) < 0) return 0;
  return static_cast<std::int32_t>(st.current_count);
}

bool DdsPublisher::wait_for_subscribers(std::int32_t count, bool (*stop)()) const {
  constexpr std::int64_t kPoll = 20'000'000;
  while (matched() < count) {
    if (stop != nullptr && stop()) return false;
    sleep_until(monotonic_ns() + kPoll);  // a signal ends it early: stop is looked at next
  }
  return true;
}

// ---------------------------------------------------------------------------------------------
Result<std::unique_ptr<DdsSubscription>> DdsSubscription::create(const DdsContext& context,
                                                                 const DdsTopic& raw,
                                                                 const msgs::TopicSpec* spec,
                                                                 const QosSpec& q,
                                                                 const EndpointOptions& options) {
  auto topic = make_raw_topic(context.participant, raw.dds_name, raw.dds_type);
  if (!topic) return topic.error();
  dds_qos_t* qos = make_qos(q, true, with_type_hash(options, raw), context.distro);
  const dds_entity_t reader = dds_create_reader(context.participant, topic.value(), qos, nullptr);
  dds_delete_qos(qos);
  if (reader < 0) {
    dds_delete(topic.value());
    return dds_error("cannot create DDS reader for " + raw.dds_name, reader);
  }
  dds_set_status_mask(reader,
                      DDS_DATA_AVAILABLE_STATUS | DDS_SAMPLE_LOST_STATUS | DDS_SAMPLE_REJECTED_STATUS);
  std::unique_ptr<DdsSubscription> s(new DdsSubscription());
  s->reader_ = reader;
  s->topic_ = topic.value();
  s->spec_ = spec;
  s->q_ = q;
  s->graph_ = list_endpoint(context, Graph::Kind::Reader, reader, options.in_graph);
  return s;
}

DdsSubscription::~DdsSubscription() {
  if (reader_ > 0) unlist_endpoint(graph_, reader_);
  if (reader_ > 0) dds_delete(reader_);
  if (topic_ > 0) dds_delete(topic_);
}

namespace {
void release_serdata(void* d) {
  ddsi_serdata_unref(static_cast<ddsi_serdata*>(d));
}
}  // namespace

bool DdsSubscription::take(Received& out) {
  while (true) {
    ddsi_serdata* d = nullptr;
    dds_sample_info_t info{};
    const dds_return_t n = dds_takecdr(reader_, &d, 1, &info, DDS_ANY_STATE);
    if (n <= 0) return false;
    if (!info.valid_data) {
      ddsi_serdata_unref(d);
      continue;
    }
    // Borrowed, not copied: to_ser_ref hands out a reference to the sample and its contiguous
    // bytes (rbsim's raw CDR type keeps them in one buffer).
    const std::uint32_t size = ddsi_serdata_size(d);
    ddsrt_iovec_t bytes{};
    out.held = Loan(ddsi_serdata_to_ser_ref(d, 0, size, &bytes), &release_serdata);
    ddsi_serdata_unref(d);
    out.cdr = {static_cast<const std::byte*>(bytes.iov_base), bytes.iov_len};
    out.source_time_ns = info.source_timestamp;
    auto known = std::find_if(writers_.begin(), writers_.end(),
                              [&](const Writer& w) { return w.handle == info.publication_handle; });
    if (known == writers_.end()) {
      Writer w{info.publication_handle, {}, spec_ != nullptr ? msgs::offered_qos(*spec_) : q_};
      if (dds_builtintopic_endpoint_t* e =
              dds_get_matched_publication_data(reader_, info.publication_handle)) {
        std::memcpy(w.guid.data(), e->key.v, w.guid.size());
        offered_by(e->qos, w.offered);
        dds_builtintopic_free_endpoint(e);
      } else {  // the writer is gone already: its handle is all there is to tell it apart
        std::memcpy(w.guid.data(), &info.publication_handle, sizeof info.publication_handle);
      }
      writers_.push_back(w);
      known = writers_.end() - 1;
    }
    out.writer = known->guid;
    out.offered = known->offered;
    return true;
  }
}

std::uint64_t DdsSubscription::lost() const {
  dds_sample_lost_status_t lost{};
  dds_sample_rejected_status_t rejected{};
  dds_get_sample_lost_status(reader_, &lost);
  dds_get_sample_rejected_status(reader_, &rejected);
  return static_cast<std::uint64_t>(lost.total_count) + static_cast<std::uint64_t>(rejected.total_count);
}

std::int32_t DdsSubscription::matched() const {
  dds_subscription_matched_status_t st{};
  if (dds_get_subscription_matched_status(reader_, &st) < 0) return 0;
  return static_cast<std::int32_t>(st.current_count);
}

// ---------------------------------------------------------------------------------------------
Result<std::unique_ptr<WaitSetImpl>> DdsParticipant::create_waitset() {
  const dds_entity_t handle = dds_create_waitset(context_.participant);
  if (handle < 0) return Error{std::string("cannot create a DDS waitset: ") + dds_strretcode(handle)};
  return std::unique_ptr<WaitSetImpl>(new DdsWaitSet(handle));
}

DdsWaitSet::~DdsWaitSet() {
  if (handle_ > 0) dds_delete(handle_);
}

void DdsWaitSet::attach(SubscriptionImpl& subscription) {
  dds_waitset_attach(handle_, static_cast<DdsSubscription&>(subscription).reader(),
                     static_cast<dds_attach_t>(attached_++));
}

Result<std::int32_t> DdsWaitSet::wait(std::int64_t timeout_ns) {
  dds_attach_t triggered[16];
  const dds_return_t n = dds_waitset_wait(handle_, triggered, 16, timeout_ns);
  if (n < 0) return Error{std::string("DDS wait failed: ") + dds_strretcode(n)};
  return static_cast<std::int32_t>(n);
}

// ---------------------------------------------------------------------------------------------
namespace {
const DdsParticipant* dds_of(const Participant& p) {
  return dynamic_cast<const DdsParticipant*>(&p.impl());
}
}  // namespace

std::int32_t dds_entity(const Participant& participant) {
  const DdsParticipant* p = dds_of(participant);
  return p != nullptr ? p->context().participant : 0;
}
std::int32_t dds_entity(const Publisher& publisher) {
  const auto* p = dynamic_cast<const DdsPublisher*>(&publisher.impl());
  return p != nullptr ? p->writer() : 0;
}
std::int32_t dds_entity(const Subscription& subscription) {
  const auto* s = dynamic_cast<const DdsSubscription*>(&subscription.impl());
  return s != nullptr ? s->reader() : 0;
}
std::uint32_t dds_domain(const Participant& participant) {
  const DdsParticipant* p = dds_of(participant);
  return p != nullptr ? p->domain() : 0;
}
RosDistro dds_distro(const Participant& participant) {
  const DdsParticipant* p = dds_of(participant);
  return p != nullptr ? p->context().distro : RosDistro::Jazzy;
}

}  // namespace rbsim::node
