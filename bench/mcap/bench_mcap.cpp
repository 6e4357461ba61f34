// MCAP recording and reading throughput, and the cost --record adds to a run (scripts/bench-mcap).
//
//   BM_Encode/N                 rbsim_msgs/BodyStates CDR encoding only (msgs::Encoder), N bodies
//   BM_Write/<codec>/N          encode BodyStates of an N-body builders::grid world + Writer into a
//                               file (open, ~8 MB of messages, close): codec none | lz4 | zstd
//   BM_Read/<codec>/N           IndexedReader::read_messages over such a file (chunk CRCs checked)
//   BM_ReadDecode/<codec>/N     the same plus MessageDecoder::decode of every message (the generic,
//                               schema-driven decoder `rbsim log check/export` use), checking the
//                               decoded body count
//   BM_ReadTyped/<codec>/N      the same with the typed msgs::decode_body_states instead
//   BM_Check/<codec>/N          rbsim check (check::check_logs) of such a file against a copy
//   BM_CheckDiffers/<codec>/N   ... against a file whose every message differs (all values compared)
//   BM_Record/<variant>         one `rbsim run`-equivalent run of builders::grid(1000, true) for
//                               RBSIM_BENCH_RECORD_STEPS steps (default 2000): World::step,
//                               find_nonfinite, sinks; sink begin and finish are timed too
//     off                         no sink (the baseline)
//     all_zstd|all_lz4|all_none   recordings::make_mcap_sink, the default topics (what --record does)
//     body_states                 only /rbsim/body_states (McapSinkOptions::topics), zstd
//     tf                          only /tf, zstd
//     every_topic                 every topic, poses included, zstd
//     every10, every100           the default topics, zstd, --record-every 10 / 100
//     body_states_every10         only /rbsim/body_states, zstd, --record-every 10
//
// Throughput: bytes_per_second / items_per_second count uncompressed message bytes / messages
// (MCAP record framing and compression excluded), over wall-clock time (real_time, manual time for
// BM_Record); Google Benchmark's CPU column is the thread's CPU time (user + system, so file
// writes count), the whole process's for BM_Write, BM_Record (recordings compress on a second
// thread) and BM_Check* (rbsim check reads each file on a thread of its own). scripts/bench-mcap judges
// on wall-clock time, as a user sees it, and prints the CPU figures beside it. BM_Check* also count
// the minor page faults per check ("faults": first touches of fresh memory, which the kernel
// zeroes page by page). Files go to $RBSIM_BENCH_TMP (default /tmp) and are removed afterwards.
#include <benchmark/benchmark.h>
#include <sys/resource.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "rbsim/builders.hpp"
#include "rbsim/check.hpp"
#include "rbsim/core.hpp"
#include "rbsim/mcap.hpp"
#include "rbsim/mcap_sink.hpp"
#include "rbsim/msgs.hpp"
#include "rbsim/scene.hpp"
#include "rbsim/sink.hpp"

namespace {

using namespace rbsim;

constexpr std::int64_t kSizes[] = {100, 10'000};
constexpr std::size_t kFileBytes = 8u << 20;   // uncompressed message bytes per file
constexpr std::size_t kChunkBytes = 1u << 20;  // the recorder's chunk size (recordings::McapSinkOptions)
constexpr std::int32_t kRecordBodies = 1000;

std::string temp_path(const std::string& tag) {
  const char* dir = std::getenv("RBSIM_BENCH_TMP");
  return std::string(dir != nullptr && *dir != '\0' ? dir : "/tmp") + "/rbsim_bench_mcap_" +
         std::to_string(::getpid()) + "_" + tag + ".mcap";
}

// A Scene around builders::grid (the encoders need its colours).
Scene grid_scene(std::int32_t n, bool wind_and_springs) {
  Scene s;
  s.path = s.name = "grid" + std::to_string(n);
  s.world = builders::grid(n, wind_and_springs);
  s.duration = 1.0;
  s.viewport = Viewport{0.0, 0.0, 10.0};
  for (std::int32_t b = 0; b < n; ++b) {
    s.body_colors.push_back(Color{0.2 + 0.6 * (b % 7) / 7.0, 0.4, 0.6});
  }
  s.spring_colors.assign(s.world.springs.size(), Color{0.25, 0.25, 0.25});
  return s;
}

// N-body grid world after each of its first steps (wind and springs on, so every state moves): enough
// distinct states that no chunk repeats a message, so compressors see what a real run gives them.
struct Snapshots {
  Scene scene;
  std::vector<World> worlds;
};

const Snapshots& snapshots(std::int32_t n) {
  static std::vector<std::pair<std::int32_t, std::unique_ptr<Snapshots>>> cache;
  for (auto& [size, s] : cache) {
    if (size == n) return *s;
  }
  auto s = std::make_unique<Snapshots>();
  s->scene = grid_scene(n, true);
  auto created = World::create(s->scene.world);
  if (!created) {
    std::fprintf(stderr, "bench_mcap: %s\n", created.error().message.c_str());
    std::exit(1);
  }
  World w = std::move(created.value());
  msgs::Bytes probe;
  msgs::Encoder(s->scene).body_states(w, probe);
  const std::size_t count = std::max<std::size_t>(16, 2 * kChunkBytes / probe.size() + 1);
  for (std::size_t i = 0; i < count; ++i) {
    w.step();
    s->worlds.push_back(w);
  }
  cache.emplace_back(n, std::move(s));
  return *cache.back().second;
}

std::size_t messages_per_file(std::size_t message_size) {
  return std::max<std::size_t>(16, kFileBytes / std::max<std::size_t>(message_size, 1));
}

// Writes `count` BodyStates messages (encoded from the snapshots in turn) to `path`. Returns the
// uncompressed message bytes, or 0 after reporting an error into `state`.
struct Codec {
  const char* name;
  mcap::Compression compression;
  int level;  // 0: the codec's default (what rbsim records with)
};

std::uint64_t write_file(benchmark::State& state, const std::string& path, const Codec& codec,
                         const Snapshots& snaps, const msgs::Encoder& encoder, std::size_t count,
                         msgs::Bytes& buf, std::size_t first_snapshot = 0) {
  mcap::Writer writer;
  mcap::WriterOptions options = recordings::writer_options(codec.compression);
  options.compression_level = codec.level;
  if (auto st = writer.open(path, options); !st.ok()) {
    state.SkipWithError(st.error().message.c_str());
    return 0;
  }
  auto channel = recordings::add_topic(writer, msgs::topic(msgs::TopicId::BodyStates), "rbsim");
  if (!channel.ok()) {
    state.SkipWithError(channel.error().message.c_str());
    return 0;
  }
  std::uint64_t bytes = 0;
  for (std::size_t i = 0; i < count; ++i) {
    encoder.body_states(snaps.worlds[(first_snapshot + i) % snaps.worlds.size()], buf);
    const mcap::Timestamp t = static_cast<mcap::Timestamp>(i) * 1'000'000;
    if (auto st = writer.write_message(channel.value(), static_cast<std::uint32_t>(i), t, t, buf); !st.ok()) {
      state.SkipWithError(st.error().message.c_str());
      return 0;
    }
    bytes += buf.size();
  }
  if (auto st = writer.close(); !st.ok()) {
    state.SkipWithError(st.error().message.c_str());
    return 0;
  }
  return bytes;
}

std::size_t body_states_size(const Snapshots& snaps) {
  msgs::Encoder encoder(snaps.scene);
  msgs::Bytes buf;
  encoder.body_states(snaps.worlds[0], buf);
  return buf.size();
}

void set_throughput(benchmark::State& state, std::uint64_t bytes_per_iteration, std::size_t messages) {
  state.SetBytesProcessed(static_cast<std::int64_t>(bytes_per_iteration) * state.iterations());
  state.SetItemsProcessed(static_cast<std::int64_t>(messages) * state.iterations());
}

// ---------------------------------------------------------------------------------------------

void bm_encode(benchmark::State& state) {
  const Snapshots& snaps = snapshots(static_cast<std::int32_t>(state.range(0)));
  const msgs::Encoder encoder(snaps.scene);
  msgs::Bytes buf;
  std::size_t i = 0;
  std::uint64_t bytes = 0;
  for (auto _ : state) {
    encoder.body_states(snaps.worlds[i++ % snaps.worlds.size()], buf);
    bytes += buf.size();
    benchmark::DoNotOptimize(buf.data());
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(bytes));
  state.SetItemsProcessed(state.iterations());
}

void bm_write(benchmark::State& state, Codec codec) {
  const Snapshots& snaps = snapshots(static_cast<std::int32_t>(state.range(0)));
  const msgs::Encoder encoder(snaps.scene);
  const std::size_t count = messages_per_file(body_states_size(snaps));
  const std::string path = temp_path("write");
  msgs::Bytes buf;
  std::uint64_t bytes = 0;
  for (auto _ : state) {
    bytes = write_file(state, path, codec, snaps, encoder, count, buf);
    if (bytes == 0) break;
  }
  std::error_code ec;
  const auto file_size = std::filesystem::file_size(path, ec);
  std::filesystem::remove(path, ec);
  set_throughput(state, bytes, count);
  state.counters["messages_per_file"] = static_cast<double>(count);
  state.counters["file_per_raw"] =
      bytes > 0 ? static_cast<double>(file_size) / static_cast<double>(bytes) : 0.0;
}

enum class Decode { None, Generic, Typed };

void bm_read(benchmark::State& state, Codec codec, Decode mode) {
  const bool decode = mode != Decode::None;
  const Snapshots& snaps = snapshots(static_cast<std::int32_t>(state.range(0)));
  const msgs::Encoder encoder(snaps.scene);
  const std::size_t count = messages_per_file(body_states_size(snaps));
  const std::string path = temp_path(mode == Decode::None      ? "read"
                                     : mode == Decode::Generic ? "read_decode"
                                                               : "read_typed");
  msgs::Bytes buf;
  const std::uint64_t bytes = write_file(state, path, codec, snaps, encoder, count, buf);
  if (bytes == 0) return;
  const std::uint64_t bodies = static_cast<std::uint64_t>(snaps.worlds[0].body_count());

  std::vector<msgs::Scalar> scalars;
  msgs::BodyStatesMessage typed;
  std::uint64_t seen_bytes = 0, seen_messages = 0;
  for (auto _ : state) {
    mcap::IndexedReader reader;
    if (auto st = reader.open(path); !st.ok()) {
      state.SkipWithError(st.error().message.c_str());
      break;
    }
    std::optional<msgs::MessageDecoder> decoder;
    std::string error;
    seen_bytes = seen_messages = 0;
    auto st = reader.read_messages({}, [&](const mcap::MessageEntry& e) {
      seen_bytes += e.message.data.size();
      ++seen_messages;
      if (!decode) {
        benchmark::DoNotOptimize(e.message.data.data());
        return true;
      }
      const std::span<const std::byte> cdr = e.message.data;
      if (mode == Decode::Typed) {
        if (Status ds = msgs::decode_body_states(cdr, typed); !ds) return error = ds.error().message, false;
        if (typed.bodies.size() != bodies) return error = "decoded body count differs", false;
        benchmark::DoNotOptimize(typed.bodies.data());
        return true;
      }
      if (!decoder) {
        if (e.schema == nullptr) return error = "message without schema", false;
        auto created = msgs::MessageDecoder::create(
            e.schema->name, {reinterpret_cast<const char*>(e.schema->data.data()), e.schema->data.size()});
        if (!created) return error = created.error().message, false;
        decoder.emplace(std::move(created.value()));
      }
      if (Status ds = decoder->decode(cdr, scalars); !ds) return error = ds.error().message, false;
      // The check: header stamp (2), frame_id, step, then the body count.
      if (scalars.size() < 5 || scalars[4].u != bodies) return error = "decoded body count differs", false;
      benchmark::DoNotOptimize(scalars.data());
      return true;
    });
    if (!st.ok()) error = st.error().message;
    if (!error.empty() || seen_messages != count || seen_bytes != bytes) {
      if (error.empty())
        error = "read " + std::to_string(seen_messages) + " messages, wrote " + std::to_string(count);
      state.SkipWithError(error.c_str());
      break;
    }
  }
  std::error_code ec;
  std::filesystem::remove(path, ec);
  set_throughput(state, bytes, count);
}

// rbsim check (check::check_logs) of a file against a copy, what a CI gate on a golden made by the
// same binary does (identical messages take the byte-equal path), or, `differ`, against a file
// whose every message is a snapshot later: every value is decoded, compared and tabulated (and
// the check reports the divergence). Bytes: one file's message data.
void bm_check(benchmark::State& state, Codec codec, bool differ) {
  const Snapshots& snaps = snapshots(static_cast<std::int32_t>(state.range(0)));
  const msgs::Encoder encoder(snaps.scene);
  const std::size_t count = messages_per_file(body_states_size(snaps));
  const std::string run = temp_path(differ ? "check_differs_run" : "check_run");
  const std::string golden = temp_path(differ ? "check_differs_golden" : "check_golden");
  msgs::Bytes buf;
  const std::uint64_t bytes = write_file(state, run, codec, snaps, encoder, count, buf);
  if (bytes == 0 || write_file(state, golden, codec, snaps, encoder, count, buf, differ ? 1 : 0) == 0) return;
  rusage usage{};
  ::getrusage(RUSAGE_SELF, &usage);
  const long faults_before = usage.ru_minflt;
  for (auto _ : state) {
    auto report = check::check_logs(run, golden);
    if (!report) {
      state.SkipWithError(report.error().message.c_str());
      break;
    }
    if (report->messages != count || report->passed() == differ) {
      state.SkipWithError("check compared the wrong messages or gave the wrong verdict");
      break;
    }
  }
  ::getrusage(RUSAGE_SELF, &usage);
  // Minor page faults per check (first touches of fresh memory: the kernel zeroes each page).
  state.counters["faults"] = benchmark::Counter(static_cast<double>(usage.ru_minflt - faults_before),
                                                benchmark::Counter::kAvgIterations);
  std::error_code ec;
  std::filesystem::remove(run, ec);
  std::filesystem::remove(golden, ec);
  set_throughput(state, bytes, count);
}

// ---------------------------------------------------------------------------------------------
// The cost of --record in a run.

struct RecordVariant {
  const char* name;
  bool record = false;
  mcap::Compression compression = mcap::Compression::Zstd;
  msgs::TopicSet topics;
  std::int64_t every = 1;
};

std::int64_t record_steps() {
  const char* env = std::getenv("RBSIM_BENCH_RECORD_STEPS");
  const long long v = env != nullptr ? std::atoll(env) : 0;
  return v > 0 ? v : 2000;
}

void bm_record(benchmark::State& state, const RecordVariant& v) {
  static const Scene scene = grid_scene(kRecordBodies, true);
  static const World initial = [] {
    auto created = World::create(scene.world);
    if (!created) {
      std::fprintf(stderr, "bench_mcap: %s\n", created.error().message.c_str());
      std::exit(1);
    }
    return std::move(created.value());
  }();
  const std::int64_t steps = record_steps();
  const std::string path = temp_path(std::string("record_") + v.name);
  std::uint64_t file_size = 0, raw_size = 0;
  for (auto _ : state) {
    World world = initial;  // untimed: the run starts from the loaded scene
    std::unique_ptr<Sink> sink;
    if (v.record) {
      recordings::McapSinkOptions ro;
      ro.compression = v.compression;
      ro.topics = v.topics;
      ro.every = v.every;
      sink = recordings::make_mcap_sink(path, ro);
    }
    const auto t0 = std::chrono::steady_clock::now();
    bool ok = true;
    if (sink && !sink->begin(scene, world)) ok = false;
    while (ok && world.step_index() < steps) {
      world.step();
      if (world.find_nonfinite()) ok = false;
      if (sink && !sink->write(world)) ok = false;
    }
    if (ok && sink && !sink->finish()) ok = false;
    const auto t1 = std::chrono::steady_clock::now();
    if (!ok) {
      state.SkipWithError("run or recording failed");
      break;
    }
    state.SetIterationTime(std::chrono::duration<double>(t1 - t0).count());
  }
  if (v.record) {
    mcap::IndexedReader reader;
    if (reader.open(path).ok()) {
      file_size = reader.file_size();
      for (const auto& ci : reader.chunk_indexes()) raw_size += ci.uncompressed_size;
    }
    std::error_code ec;
    std::filesystem::remove(path, ec);
  }
  state.counters["steps"] = static_cast<double>(steps);
  state.counters["file_MB"] = static_cast<double>(file_size) / 1e6;
  state.counters["raw_MB"] = static_cast<double>(raw_size) / 1e6;  // uncompressed chunk records
}

void register_all() {
  for (std::int64_t n : kSizes) benchmark::RegisterBenchmark("BM_Encode", bm_encode)->Arg(n);
  const Codec codecs[] = {{"none", mcap::Compression::None, 0},
                          {"lz4", mcap::Compression::Lz4, 0},
                          {"zstd", mcap::Compression::Zstd, 0}};
  for (const Codec& c : codecs) {
    const std::string codec = c.name;
    for (std::int64_t n : kSizes) {
      benchmark::RegisterBenchmark(("BM_Write/" + codec).c_str(), bm_write, c)
          ->Arg(n)
          ->MeasureProcessCPUTime()
          ->UseRealTime()
          ->Unit(benchmark::kMillisecond);
      benchmark::RegisterBenchmark(("BM_Read/" + codec).c_str(), bm_read, c, Decode::None)
          ->Arg(n)
          ->UseRealTime()
          ->Unit(benchmark::kMillisecond);
      benchmark::RegisterBenchmark(("BM_ReadDecode/" + codec).c_str(), bm_read, c, Decode::Generic)
          ->Arg(n)
          ->UseRealTime()
          ->Unit(benchmark::kMillisecond);
      benchmark::RegisterBenchmark(("BM_ReadTyped/" + codec).c_str(), bm_read, c, Decode::Typed)
          ->Arg(n)
          ->UseRealTime()
          ->Unit(benchmark::kMillisecond);
      benchmark::RegisterBenchmark(("BM_Check/" + codec).c_str(), bm_check, c, false)
          ->Arg(n)
          ->MeasureProcessCPUTime()
          ->UseRealTime()
          ->Unit(benchmark::kMillisecond);
      benchmark::RegisterBenchmark(("BM_CheckDiffers/" + codec).c_str(), bm_check, c, true)
          ->Arg(n)
          ->MeasureProcessCPUTime()
          ->UseRealTime()
          ->Unit(benchmark::kMillisecond);
    }
  }
  // Other zstd levels (rbsim records with 1, the MCAP C++ library's default): what they cost.
  const Codec levels[] = {{"zstd_level3", mcap::Compression::Zstd, 3},
                          {"zstd_level-3", mcap::Compression::Zstd, -3}};
  for (const Codec& c : levels) {
    benchmark::RegisterBenchmark((std::string("BM_Write/") + c.name).c_str(), bm_write, c)
        ->Arg(10'000)
        ->MeasureProcessCPUTime()
        ->UseRealTime()
        ->Unit(benchmark::kMillisecond);
  }
  using T = msgs::TopicId;
  const auto only = [](std::initializer_list<T> ids) {
    msgs::TopicSet set;
    for (T id : ids) set.set(static_cast<std::size_t>(id));
    return set;
  };
  const msgs::TopicSet all = msgs::default_topics();
  static const std::vector<RecordVariant> variants = {
      {"off", false, mcap::Compression::Zstd, all, 1},
      {"all_zstd", true, mcap::Compression::Zstd, all, 1},
      {"all_lz4", true, mcap::Compression::Lz4, all, 1},
      {"all_none", true, mcap::Compression::None, all, 1},
      {"body_states", true, mcap::Compression::Zstd, only({T::BodyStates}), 1},
      {"tf", true, mcap::Compression::Zstd, only({T::Tf}), 1},
      {"every_topic", true, mcap::Compression::Zstd, msgs::TopicSet().set(), 1},
      {"every10", true, mcap::Compression::Zstd, all, 10},
      {"every100", true, mcap::Compression::Zstd, all, 100},
      {"body_states_every10", true, mcap::Compression::Zstd, only({T::BodyStates}), 10},
  };
  for (const RecordVariant& v : variants) {
    benchmark::RegisterBenchmark((std::string("BM_Record/") + v.name).c_str(), bm_record, v)
        ->UseManualTime()
        ->MeasureProcessCPUTime()
        ->Iterations(1)
        ->Unit(benchmark::kMillisecond);
  }
}

}  // namespace

int main(int argc, char** argv) {
  register_all();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
