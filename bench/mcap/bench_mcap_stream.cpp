// Writes a captured message stream with rbsim's MCAP writer, or as plain buffered bytes, and times
// it (scripts/bench-mcap-sdk compares it with the Foxglove SDK's writer, bench/mcap/sdk_compare.py).
//
//   rbsim_bench_mcap_stream capture SCENE STEPS CAPTURE
//   rbsim_bench_mcap_stream CAPTURE OUT --writer rbsim|plain [--compression none|lz4|zstd]
//                           [--level N] [--chunk-size BYTES] [--crc on|off] [--threads 1|2]
//
// `capture` runs SCENE for STEPS steps through the run driver and the MCAP sink of
// `rbsim run --record` (default topics, uncompressed chunks): the message stream of that run.
// Otherwise CAPTURE is any MCAP file: its schemas, channels and messages (ids, sequences, log and
// publish times, payloads) are read into memory first, untimed. Then, timed on the wall clock:
//   rbsim   mcap::Writer::open(OUT) with recordings::writer_options() (what rbsim run --record uses) and
//           the given compression, level, chunk size and CRCs; --threads 2 compresses on a second
//           thread (WriterOptions::background_compression, as recordings do), 1 on the caller's;
//           the same schema and channel records; every message in capture order; close()
//   plain   std::fopen(OUT), one std::fwrite of each message's payload (stdio's buffer), fclose
// Prints one JSON line: {"seconds", "cpu_seconds", "messages", "payload_bytes", "file_bytes"}
// (cpu_seconds: user + system time of the whole process over the timed part, every thread).
// Throughput is payload_bytes / seconds (the record framing, indexes and summary are the writer's
// own cost).
// Exit status 0 on success, 1 on an I/O or MCAP error, 2 on a usage error.
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "rbsim/mcap.hpp"
#include "rbsim/mcap_sink.hpp"
#include "rbsim/run.hpp"
#include "rbsim/scene.hpp"

namespace {

using namespace rbsim;

struct Capture {
  std::vector<mcap::Schema> schemas;
  std::vector<mcap::Channel> channels;
  std::vector<mcap::Message> messages;
  std::uint64_t payload_bytes = 0;
};

// Keeps the first record of each id, in order (schemas and channels).
template <class Record>
void keep_first_of_each_id(std::vector<Record>& records) {
  std::vector<Record> kept;
  for (auto& r : records) {
    if (std::none_of(kept.begin(), kept.end(), [&](const Record& k) { return k.id == r.id; }))
      kept.push_back(std::move(r));
  }
  records = std::move(kept);
}
bool load(const std::string& path, Capture& out) {
  mcap::StreamReader reader;
  if (auto st = reader.open(path); !st.ok()) {
    std::fprintf(stderr, "%s: %s\n", path.c_str(), st.error().message.c_str());
    return false;
  }
  mcap::RecordEntry entry;
  while (reader.next(entry)) {  // bounded: each call consumes at least one record of the file
    if (auto* s = std::get_if<mcap::Schema>(&entry.record)) {
      out.schemas.push_back(std::move(*s));
    } else if (auto* c = std::get_if<mcap::Channel>(&entry.record)) {
      out.channels.push_back(std::move(*c));
    } else if (auto* m = std::get_if<mcap::Message>(&entry.record)) {
      out.payload_bytes += m->data.size();
      out.messages.push_back(std::move(*m));
    }
  }
  if (!reader.status().ok()) {
    std::fprintf(stderr, "%s: %s\n", path.c_str(), reader.status().error().message.c_str());
    return false;
  }
  // A capture written with a summary repeats its schemas and channels there: keep the first of each.
  keep_first_of_each_id(out.schemas);
  keep_first_of_each_id(out.channels);
  return true;
}

int write_rbsim(const Capture& cap, const std::string& path, const mcap::WriterOptions& options) {
  mcap::Writer writer;
  Status st = writer.open(path, options);
  for (const auto& s : cap.schemas) {
    if (st.ok()) st = writer.add_schema(s);
  }
  for (const auto& c : cap.channels) {
    if (st.ok()) st = writer.add_channel(c);
  }
  for (const auto& m : cap.messages) {
    if (!st.ok()) break;
    st = writer.write_message(m.channel_id, m.sequence, m.log_time, m.publish_time, m.data);
  }
  if (st.ok()) {
    st = writer.close();
  } else {
    (void)writer.close();
  }
  if (!st.ok()) {
    std::fprintf(stderr, "%s: %s\n", path.c_str(), st.error().message.c_str());
    return 1;
  }
  return 0;
}

int write_plain(const Capture& cap, const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr) {
    std::perror(path.c_str());
    return 1;
  }
  bool ok = true;
  for (const auto& m : cap.messages) {
    ok = ok && std::fwrite(m.data.data(), 1, m.data.size(), f) == m.data.size();
  }
  ok = std::fclose(f) == 0 && ok;
  if (!ok) std::perror(path.c_str());
  return ok ? 0 : 1;
}

int capture(const std::string& scene_path, const std::string& steps_text, const std::string& out) {
  const std::int64_t steps = std::atoll(steps_text.c_str());
  Result<Scene> scene = load_scene(scene_path);
  if (!scene || steps < 1) {
    std::fprintf(stderr, "capture: %s\n", scene ? "STEPS must be >= 1" : scene.error().message.c_str());
    return scene ? 2 : 1;
  }
  Result<Driver> driver = Driver::create(scene.value());
  if (!driver) {
    std::fprintf(stderr, "capture: %s\n", driver.error().message.c_str());
    return 1;
  }
  recordings::McapSinkOptions options;  // the default topics, as rbsim run --record
  options.compression = mcap::Compression::None;
  auto sink = recordings::make_mcap_sink(out, options);
  driver->add(*sink);
  DriverOptions run;
  run.steps = steps;
  if (Status st = driver->run_pass(run); !st) {
    std::fprintf(stderr, "capture: %s\n", st.error().message.c_str());
    return 1;
  }
  return 0;
}

double cpu_seconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         1e-6 * static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

int usage(const char* what) {
  std::fprintf(stderr,
               "rbsim_bench_mcap_stream: %s\nusage: rbsim_bench_mcap_stream capture SCENE STEPS CAPTURE\n"
               "       rbsim_bench_mcap_stream CAPTURE OUT --writer rbsim|plain "
               "[--compression none|lz4|zstd] [--level N] [--chunk-size BYTES] [--crc on|off] "
               "[--threads 1|2]\n",
               what);
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc == 5 && std::string_view(argv[1]) == "capture") return capture(argv[2], argv[3], argv[4]);
  if (argc < 3) return usage("missing CAPTURE or OUT");
  const std::string capture_path = argv[1];
  const std::string out_path = argv[2];
  std::string writer = "rbsim";
  mcap::Compression compression = mcap::Compression::None;
  int level = 0;
  std::uint64_t chunk_size = 1 << 20;
  bool crc = true;
  int threads = 1;
  for (int i = 3; i < argc; i += 2) {
    const std::string_view flag = argv[i];
    if (i + 1 >= argc) return usage("option without a value");
    const std::string value = argv[i + 1];
    if (flag == "--writer" && (value == "rbsim" || value == "plain")) {
      writer = value;
    } else if (flag == "--compression" && mcap::parse_compression(value, compression)) {
    } else if (flag == "--level") {
      level = std::atoi(value.c_str());
    } else if (flag == "--chunk-size" && std::strtoull(value.c_str(), nullptr, 10) > 0) {
      chunk_size = std::strtoull(value.c_str(), nullptr, 10);
    } else if (flag == "--crc" && (value == "on" || value == "off")) {
      crc = value == "on";
    } else if (flag == "--threads" && (value == "1" || value == "2")) {
      threads = value == "2" ? 2 : 1;
    } else {
      return usage(("bad option " + std::string(flag) + " " + value).c_str());
    }
  }
  if (const std::string bad = mcap::check_compression_level(compression, level); !bad.empty()) {
    return usage(bad.c_str());
  }

  Capture cap;
  if (!load(capture_path, cap)) return 1;
  mcap::WriterOptions options = recordings::writer_options(compression, chunk_size, level);
  options.enable_crcs = crc;
  options.background_compression = threads == 2;

  const double c0 = cpu_seconds();
  const auto t0 = std::chrono::steady_clock::now();
  const int rc = writer == "plain" ? write_plain(cap, out_path) : write_rbsim(cap, out_path, options);
  const auto t1 = std::chrono::steady_clock::now();
  const double c1 = cpu_seconds();
  if (rc != 0) return rc;
  std::error_code ec;
  const auto file_bytes = std::filesystem::file_size(out_path, ec);
  std::printf(
      "{\"seconds\": %.9f, \"cpu_seconds\": %.6f, \"messages\": %zu, \"payload_bytes\": %llu, "
      "\"file_bytes\": %llu}\n",
      std::chrono::duration<double>(t1 - t0).count(), c1 - c0, cap.messages.size(),
      static_cast<unsigned long long>(cap.payload_bytes),
      static_cast<unsigned long long>(ec ? 0 : file_bytes));
  return 0;
}
