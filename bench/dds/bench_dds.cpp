// Publish-to-receive latency of the 100-body BodyStates message over Cyclone DDS on loopback,
// measured like ddsperf's ping/pong: `rbsim_bench_dds pong` echoes every sample of /bench/ping
// back on /bench/pong; `rbsim_bench_dds ping N` sends N samples one at a time and reports half
// the round-trip times (median and p99, microseconds).
// `rbsim_bench_dds listen TOPIC SECONDS` subscribes to a node's BodyStates topic (its QoS) and, for
// every sample, prints "STEP SOURCE_NS DECODED_NS SOURCE_MONO_NS": the writer's source timestamp
// and the wall clock once decoded (both CLOCK_REALTIME), and the source timestamp on
// CLOCK_MONOTONIC, the clock of Node's process.hrtime (the two clocks' offset is read beside each
// sample): the DDS side of scripts/bench-foxglove's latency.
#include <dds/dds.h>
#include <dds/ddsi/ddsi_serdata.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "rbsim/builders.hpp"
#include "rbsim/dds.hpp"

namespace {

using Clock = std::chrono::steady_clock;

rbsim::msgs::Bytes body_states(int bodies) {
  rbsim::Scene scene;
  scene.world = rbsim::builders::grid(bodies, false);
  for (int b = 0; b < bodies; ++b) scene.body_colors.push_back(rbsim::default_body_color(b));
  auto world = rbsim::World::create(scene.world);
  world->step();
  rbsim::msgs::Bytes out;
  rbsim::msgs::Encoder(scene).body_states(world.value(), out);
  return out;
}

bool wait_take(rbsim::node::Subscription& sub, dds_entity_t waitset, rbsim::node::Received& got,
               double seconds) {
  const auto deadline = Clock::now() + std::chrono::duration<double>(seconds);
  while (Clock::now() < deadline) {
    if (sub.take(got)) return true;
    dds_waitset_wait(waitset, nullptr, 0, DDS_MSECS(50));
  }
  return false;
}

std::int64_t realtime_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

std::int64_t monotonic_ns() {  // steady_clock is CLOCK_MONOTONIC in libstdc++
  return std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now().time_since_epoch()).count();
}

int listen(std::uint32_t domain, const std::string& topic, double seconds) {
  auto participant = rbsim::node::create_dds_participant(domain);
  if (!participant) return std::fprintf(stderr, "%s\n", participant.error().message.c_str()), 1;
  const auto& spec = rbsim::msgs::topic(rbsim::msgs::TopicId::BodyStates);
  auto sub = rbsim::node::Subscription::create(participant.value(), spec, topic, rbsim::node::qos_for(spec));
  if (!sub) return std::fprintf(stderr, "%s\n", sub.error().message.c_str()), 1;
  const dds_entity_t waitset = dds_create_waitset(dds_entity(*participant));
  dds_waitset_attach(waitset, dds_create_readcondition(dds_entity(*sub), DDS_ANY_STATE), 0);
  std::printf("READY\n");
  std::fflush(stdout);
  std::vector<std::array<std::int64_t, 4>> rows;
  rbsim::node::Received got;
  rbsim::msgs::BodyStatesMessage msg;
  const auto deadline = Clock::now() + std::chrono::duration<double>(seconds);
  while (Clock::now() < deadline) {
    if (!sub->take(got)) {
      dds_waitset_wait(waitset, nullptr, 0, DDS_MSECS(50));
      continue;
    }
    if (!rbsim::msgs::decode_body_states(got.cdr, msg)) continue;
    const std::int64_t real = realtime_ns();
    const std::int64_t mono = monotonic_ns();
    rows.push_back(
        {static_cast<std::int64_t>(msg.step), got.source_time_ns, real, got.source_time_ns - (real - mono)});
  }
  for (const auto& r : rows)
    std::printf("%lld %lld %lld %lld\n", static_cast<long long>(r[0]), static_cast<long long>(r[1]),
                static_cast<long long>(r[2]), static_cast<long long>(r[3]));
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc >= 4 && std::strcmp(argv[1], "listen") == 0) {
    const std::uint32_t domain = argc >= 6 && std::strcmp(argv[4], "--domain") == 0
                                     ? static_cast<std::uint32_t>(std::stoul(argv[5]))
                                     : 77;
    return listen(domain, argv[2], std::stod(argv[3]));
  }
  if (argc < 2 || (std::strcmp(argv[1], "ping") != 0 && std::strcmp(argv[1], "pong") != 0)) {
    std::fprintf(stderr,
                 "usage: rbsim_bench_dds ping [N] [--domain D] | pong [--domain D] | listen TOPIC SECONDS "
                 "[--domain D]\n");
    return 2;
  }
  const bool ping = std::strcmp(argv[1], "ping") == 0;
  std::uint32_t domain = 77;
  int count = 2000;
  for (int i = 2; i < argc; ++i) {
    if (std::strcmp(argv[i], "--domain") == 0 && i + 1 < argc) {
      domain = static_cast<std::uint32_t>(std::stoul(argv[++i]));
    } else {
      count = std::stoi(argv[i]);
    }
  }
  auto participant = rbsim::node::create_dds_participant(domain);
  if (!participant) return std::fprintf(stderr, "%s\n", participant.error().message.c_str()), 1;
  const auto& spec = rbsim::msgs::topic(rbsim::msgs::TopicId::BodyStates);
  rbsim::node::QosSpec qos;
  qos.depth = 1;
  auto pub =
      rbsim::node::Publisher::create(participant.value(), spec, ping ? "/bench/ping" : "/bench/pong", qos);
  auto sub =
      rbsim::node::Subscription::create(participant.value(), spec, ping ? "/bench/pong" : "/bench/ping", qos);
  if (!pub || !sub) return std::fprintf(stderr, "cannot create endpoints\n"), 1;
  const dds_entity_t waitset = dds_create_waitset(dds_entity(*participant));
  const dds_entity_t cond = dds_create_readcondition(dds_entity(*sub), DDS_ANY_STATE);
  dds_waitset_attach(waitset, cond, 0);
  rbsim::node::Received got;
  if (!ping) {
    // Echo every sample as received (its serdata, as ddsperf's pong does), until 10 s pass idle.
    auto idle_since = Clock::now();
    while (Clock::now() - idle_since < std::chrono::seconds(10)) {
      ddsi_serdata* d = nullptr;
      dds_sample_info_t info{};
      if (dds_takecdr(dds_entity(*sub), &d, 1, &info, DDS_ANY_STATE) == 1) {
        if (info.valid_data) {
          dds_writecdr(dds_entity(*pub), d);  // takes the reference
        } else {
          ddsi_serdata_unref(d);
        }
        idle_since = Clock::now();
      } else {
        dds_waitset_wait(waitset, nullptr, 0, DDS_MSECS(50));
      }
    }
    return 0;
  }
  const rbsim::msgs::Bytes sample = body_states(100);
  const auto match_deadline = Clock::now() + std::chrono::seconds(10);
  while ((pub->matched() < 1) && Clock::now() < match_deadline) dds_sleepfor(DDS_MSECS(20));
  dds_sleepfor(DDS_MSECS(300));  // let the pong's writer match our reader too
  std::vector<double> half_rtt_us;
  const int warmup = 200;
  for (int i = 0; i < warmup + count; ++i) {
    const auto t0 = Clock::now();
    if (!pub->publish(sample)) return 1;
    if (!wait_take(sub.value(), waitset, got, 5.0)) {
      std::fprintf(stderr, "ping: no pong within 5 s after %d samples\n", i);
      return 1;
    }
    const double us = std::chrono::duration<double, std::micro>(Clock::now() - t0).count() / 2.0;
    if (i >= warmup) half_rtt_us.push_back(us);
  }
  std::sort(half_rtt_us.begin(), half_rtt_us.end());
  const auto pct = [&](double p) {
    return half_rtt_us[static_cast<std::size_t>(p * static_cast<double>(half_rtt_us.size() - 1))];
  };
  std::printf("rbsim ping: %zu samples of %zu bytes, latency (half round trip) median %.1f us, p99 %.1f us\n",
              half_rtt_us.size(), sample.size(), pct(0.5), pct(0.99));
  return 0;
}
