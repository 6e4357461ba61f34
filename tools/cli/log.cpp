// rbsim log: info, doctor, recover, export, cat, filter, merge and compress on MCAP recordings.
#include <cstdint>
#include <cstdio>
#include <functional>
#include <memory>
#include <optional>
#include <string_view>

#include "cli_util.hpp"
#include "commands.hpp"
#include "rbsim/bag.hpp"
#include "rbsim/cat.hpp"
#include "rbsim/counts.hpp"
#include "rbsim/csv.hpp"
#include "rbsim/export.hpp"
#include "rbsim/mcap_tools.hpp"
#include "rbsim/outputs.hpp"
#include "rbsim/rewrite.hpp"
#include "validators.hpp"

namespace rbsim::cli {

namespace {

struct LogOptions {
  std::string file, out;
  bool strict_message_order = false;
  std::string compression = "zstd";
  std::string csv, energy_csv, ns;
  bool quiet = false;
  bool overwrite = false;
  std::vector<std::string> topics, exclude_topics, files, namespaces;
  std::optional<double> start, end;
  std::string format = "json";
  std::uint64_t chunk_size = 1u << 20;
};

// The output options of filter, merge and compress: codec and chunk size.
Result<recordings::OutputOptions> output_options(const LogOptions& o) {
  const Result<mcap::Compression> codec = compression_option(o.compression);
  if (!codec) return codec.error();
  recordings::OutputOptions out;
  out.compression = codec.value();
  out.chunk_size = o.chunk_size;
  return out;
}

// Writes one rewrite's OUT (filter, merge, compress): outputs checked first, the report on stdout.
int rewrite_command(
    const char* command, const LogOptions& o, const std::vector<std::string>& inputs,
    const std::function<Result<recordings::RewriteReport>(const recordings::OutputOptions&)>& write) {
  if (Status st = check_outputs({{o.out, "OUT"}}, inputs, o.overwrite); !st)
    return fail(command, st.error().message);
  auto options = output_options(o);
  if (!options) return fail(command, options.error().message, 2);
  auto report = write(options.value());
  if (!report) return fail(command, report.error().message);
  if (!o.quiet) std::fputs(report.value().summary(o.out).c_str(), stdout);
  std::fflush(stdout);
  return 0;
}

int filter_command(const LogOptions& o) {
  if (o.start && o.end && *o.end < *o.start)
    return fail("log filter",
                "--end " + std::to_string(*o.end) + " is before --start " + std::to_string(*o.start), 2);
  return rewrite_command("log filter", o, {o.file}, [&](const recordings::OutputOptions& output) {
    recordings::FilterOptions options;
    options.topics = o.topics;
    options.exclude_topics = o.exclude_topics;
    options.start = o.start;
    options.end = o.end;
    options.output = output;
    return recordings::filter(o.file, o.out, options);
  });
}

int merge_command(const LogOptions& o) {
  // The last positional argument is OUT.
  LogOptions m = o;
  m.out = o.files.back();
  const std::vector<std::string> inputs(o.files.begin(), o.files.end() - 1);
  if (!o.namespaces.empty() && o.namespaces.size() != inputs.size()) {
    return fail("log merge",
                "--namespaces: " + std::to_string(o.namespaces.size()) + " given for " +
                    std::to_string(inputs.size()) +
                    " inputs: give one per input, in order (\"/\" for an input that keeps its topics)",
                2);
  }
  for (const std::string& ns : o.namespaces) {
    if (const std::string problem = ns == "/" ? "" : msgs::ros_namespace_problem(ns); !problem.empty())
      return fail("log merge", "--namespaces: \"" + ns + "\" is not a ROS 2 namespace: it " + problem, 2);
  }
  return rewrite_command("log merge", m, inputs, [&](const recordings::OutputOptions& output) {
    recordings::MergeOptions options;
    options.namespaces = o.namespaces;
    options.output = output;
    return recordings::merge(inputs, m.out, options);
  });
}

int compress_command(const LogOptions& o) {
  return rewrite_command("log compress", o, {o.file}, [&](const recordings::OutputOptions& output) {
    return recordings::compress(o.file, o.out, output);
  });
}

// A bag directory: its files, then each file's summary.
int info_command(const LogOptions& o) {
  const Result<std::vector<std::string>> files = recordings::recording_files(o.file);
  if (!files) return fail("log info", files.error().message);
  const bool bag = files->size() != 1 || files->front() != o.file;
  if (bag) {
    std::printf("bag:         %s (rosbag2, %zu file%s)\n", o.file.c_str(), files->size(),
                plural(files->size(), "", "s"));
    for (const std::string& f : files.value()) std::printf("  %s\n", f.c_str());
  }
  for (const std::string& f : files.value()) {
    auto info = mcap_tools::info(f);
    if (!info) return fail("log info", f + ": " + info.error().message);
    if (bag) std::printf("\n%s:\n", f.c_str());
    std::fputs(mcap_tools::format_info(info.value()).c_str(), stdout);
  }
  return 0;
}

// A bag directory: each of its files in turn; the first file with an error fails the command.
int doctor_command(const LogOptions& o) {
  mcap_tools::DoctorOptions options;
  options.strict_message_order = o.strict_message_order;
  const Result<std::vector<std::string>> files = recordings::recording_files(o.file);
  if (!files) return fail("log doctor", files.error().message);
  int status = 0;
  for (const std::string& file : files.value()) {
    std::printf("Examining %s\n", file.c_str());
    const mcap_tools::DoctorReport report = mcap_tools::doctor(file, options);
    for (const mcap_tools::DoctorFinding& f : report.findings) {
      std::printf("%s: %s\n", f.error ? "error" : "warning", f.text.c_str());
    }
    std::printf("%llu errors, %llu warnings\n", static_cast<unsigned long long>(report.errors),
                static_cast<unsigned long long>(report.warnings));
    std::fflush(stdout);
    if (!report.ok() && status == 0) {
      const std::string more =
          report.errors > 1 ? " (and " + std::to_string(report.errors - 1) + " more errors, listed on stdout)"
                            : "";
      status = fail("log doctor", file + ": " + report.first_error() + more);
    }
  }
  return status;
}

int recover_command(const LogOptions& o) {
  mcap_tools::RecoverOptions options;
  if (Status st = check_outputs({{o.out, "OUT"}}, {o.file}, o.overwrite); !st)
    return fail("log recover", st.error().message);
  const Result<mcap::Compression> codec = compression_option(o.compression);
  if (!codec) return fail("log recover", codec.error().message);
  options.compression = codec.value();
  auto report = mcap_tools::recover(o.file, o.out, options);
  if (!report) return fail("log recover", report.error().message);
  const mcap_tools::RecoverReport& r = report.value();
  if (!o.quiet) std::fputs(r.summary().c_str(), stdout);
  std::fflush(stdout);
  if (!r.input_intact) {  // as `mcap recover`: a written output is a success, the damage a warning
    std::fprintf(
        stderr,
        "rbsim log recover: warning: %s: %s; wrote %s with the %llu complete messages (chunks lost: %llu)\n",
        o.file.c_str(), r.problem.c_str(), o.out.c_str(), static_cast<unsigned long long>(r.messages),
        static_cast<unsigned long long>(r.incomplete_chunks + r.corrupt_chunks));
  }
  return 0;
}

int export_command(const LogOptions& o) {
  recordings::ExportOptions options;
  if (Status st = check_outputs({{o.csv, "--csv"}, {o.energy_csv, "--energy-csv"}}, {o.file}, o.overwrite);
      !st)
    return fail("log export", st.error().message);
  options.csv = o.csv;
  options.energy_csv = o.energy_csv;
  options.ns = o.ns;
  auto report = recordings::export_csv(o.file, options);
  if (!report) return fail("log export", report.error().message);
  for (const std::string& w : report.value().warnings) {
    std::fprintf(stderr, "rbsim log export: warning: %s: %s\n", o.file.c_str(), w.c_str());
  }
  if (!o.quiet) {
    const recordings::ExportReport& r = report.value();
    std::fprintf(stderr, "rbsim log export: %s: %llu steps (%llu..%llu)\n", o.file.c_str(),
                 static_cast<unsigned long long>(r.steps), static_cast<unsigned long long>(r.first_step),
                 static_cast<unsigned long long>(r.last_step));
  }
  return 0;
}

int cat_command(const LogOptions& o) {
  recordings::CatOptions options;
  for (const std::string& t : o.topics) {
    if (!t.empty()) options.topics.push_back(t);
  }
  options.start = o.start;
  options.end = o.end;
  options.format = o.format == "csv" ? recordings::CatFormat::Csv : recordings::CatFormat::Json;
  Status st = recordings::cat(o.file, options, [](std::string_view line) {
    std::fwrite(line.data(), 1, line.size(), stdout);
    std::fputc('\n', stdout);
  });
  std::fflush(stdout);
  if (!st) return fail("log cat", st.error().message);
  return 0;
}

struct InspectApps {
  CLI::App *info = nullptr, *doctor = nullptr, *recover = nullptr;
};

// rbsim log info | doctor | recover: any MCAP file.
InspectApps add_inspect_commands(CLI::App* app, const std::shared_ptr<LogOptions>& o) {
  CLI::App* info =
      app->add_subcommand("info",
                          "Summarise a recording: duration, topics with types and counts, chunks, "
                          "compression");
  info->add_option("file", o->file, "MCAP file or rosbag2 bag directory")->required();
  info->footer(
      "Reads the summary section (or scans a file that has none, and says so) and checks the data section "
      "CRC.\nExit status: 0 success, 1 error (unreadable, truncated or corrupted file), 2 usage error.");

  CLI::App* doctor = app->add_subcommand(
      "doctor",
      "Check a recording's structure the way 'mcap doctor' does: magic, header/footer, records, chunk CRCs "
      "and decompression, message and chunk indexes, statistics, summary offsets, data and summary CRCs");
  doctor->add_option("file", o->file, "MCAP file or rosbag2 bag directory (each of its files)")->required();
  doctor->add_flag("--strict-message-order", o->strict_message_order,
                   "Messages out of log-time order are errors (by default warnings)");
  doctor->footer(
      "Prints 'Examining FILE', then one line per problem ('error: ...' or 'warning: ...').\n"
      "Exit status: 0 no errors (warnings allowed), 1 any error, 2 usage error.");

  CLI::App* recover = app->add_subcommand(
      "recover",
      "Rebuild a valid, indexed recording from a truncated or damaged one, keeping every complete message");
  recover->add_option("in", o->file, "Damaged MCAP file")->required();
  recover->add_option("out", o->out, "Output MCAP file (written under a temporary name, then renamed)")
      ->required();
  recover->add_option("--compression", o->compression, "Chunk compression of the output")
      ->check(CLI::IsMember({"zstd", "lz4", "none"}))
      ->default_str("zstd");
  recover->add_flag("-q,--quiet", o->quiet, "No report on stdout");
  recover->add_flag("--overwrite", o->overwrite, "Replace OUT if it exists (by default it is refused)");
  recover->footer(
      "Chunks are the unit of recovery: a chunk cut off by the end of the file (or failing its CRC) is lost "
      "with "
      "its messages; every complete chunk is kept, with the same schema and channel ids, profile and "
      "library.\n"
      "Exit status: 0 OUT written (a copy of an intact input, or every complete message of a damaged one, "
      "with a warning on stderr saying what was lost), 1 nothing could be recovered (no complete message; "
      "no OUT written) or an error, 2 usage error.");

  return {info, doctor, recover};
}

struct ReadApps {
  CLI::App *exp = nullptr, *cat = nullptr;
};

// rbsim log export | cat: a recording's messages as CSV or JSON.
ReadApps add_read_commands(CLI::App* app, const std::shared_ptr<LogOptions>& o) {
  CLI::App* exp = app->add_subcommand(
      "export", "Write the CSV files 'rbsim run --csv / --energy-csv' write, from a recording of the run");
  exp->add_option("file", o->file, "MCAP file recorded by rbsim run --record")->required();
  exp->add_option("--csv", o->csv, std::string("Per-body CSV: ") + kBodyCsvColumns);
  exp->add_option("--energy-csv", o->energy_csv, std::string("Scene-wide CSV: ") + kEnergyCsvColumns);
  exp->add_option("--namespace", o->ns,
                  "ROS namespace of the recording's topics (default: the only one in the file)")
      ->check(ros_namespace());
  exp->add_flag("-q,--quiet", o->quiet, "No closing summary line");
  exp->add_flag("--overwrite", o->overwrite,
                "Replace the CSV files if they exist (by default they are refused)");
  exp->footer(
      "Byte for byte what rbsim run wrote for the recorded steps (all of them, or every k-th with "
      "--record-every k).\nExit status: 0 success, 1 error, 2 usage error.");

  CLI::App* cat = app->add_subcommand(
      "cat",
      "Print every message as one line of JSON, decoded by its schema (as 'mcap cat --json'), or one topic "
      "as CSV");
  cat->add_option("file", o->file, "MCAP file")->required();
  cat->add_option("--topics", o->topics,
                  "Only these topics, comma-separated; each as recorded (/rbsim/body_states) or by its "
                  "last name (body_states)")
      ->delimiter(',');
  cat->add_option("--start", o->start, "Only messages logged at or after this many seconds")
      ->check(non_negative());
  cat->add_option("--end", o->end, "Only messages logged before this many seconds")->check(non_negative());
  cat->add_option("--format", o->format, "json: a JSON object per message; csv: one topic as a table")
      ->check(CLI::IsMember({"json", "csv"}))
      ->default_str("json");
  cat->footer(
      "json (the default): one JSON object per line and message, in log-time order (equal times in file "
      "order):\n"
      "  {\"topic\":\"/rbsim/body_states\",\"sequence\":0,\"log_time\":0,\"publish_time\":0,\"data\":{...}}\n"
      "log_time and publish_time are integer nanoseconds as recorded. data is the message decoded from its "
      "channel's ros2msg schema as nested JSON: an object per message type, an array per array or "
      "sequence, field names as in the .msg definitions; floats shortest round-trip, NaN and infinities as "
      "null (JSON has neither); data is null for a channel without a ros2msg/CDR schema.\n"
      "csv: one topic (--topics, or the file's only one): a header log_time,publish_time,sequence,<fields> "
      "whose fields are the first message's flattened schema fields (bodies[0].x, ..., bodies.length), then "
      "one row per message; a message of another shape (other sequence lengths) is an error.\n"
      "Exit status: 0 success, 1 error (unreadable or corrupt file, a message its schema cannot decode, an "
      "unknown topic; for csv several topics or another shape), 2 usage error.");

  return {exp, cat};
}

struct RewriteApps {
  CLI::App *filter = nullptr, *merge = nullptr, *compress = nullptr;
};

// rbsim log filter | merge | compress.
RewriteApps add_rewrite_commands(CLI::App* app, const std::shared_ptr<LogOptions>& o) {
  const auto add_output_options = [o](CLI::App* sub) {
    sub->add_option("--compression", o->compression, "Chunk compression of OUT")
        ->check(CLI::IsMember({"zstd", "lz4", "none"}))
        ->default_str("zstd");
    sub->add_option("--chunk-size", o->chunk_size, "Uncompressed bytes per chunk of OUT")
        ->check(CLI::Range(std::uint64_t{1}, std::uint64_t{1} << 32))
        ->default_str("1048576");
    sub->add_flag("-q,--quiet", o->quiet, "No report on stdout");
    sub->add_flag("--overwrite", o->overwrite, "Replace OUT if it exists (by default it is refused)");
  };
  const char* rewrite_footer =
      "OUT is written under a temporary name, then renamed into place; it passes 'rbsim log doctor', and "
      "'rbsim check OUT IN' (with --topics for a selection) matches what it kept. Prints 'wrote OUT: N "
      "messages on T topics, C channels, S schemas'.\n"
      "Exit status: 0 OUT written, 1 error (unreadable or corrupt input, an unknown topic, OUT unwritable or "
      "existing without --overwrite; no OUT written), 2 usage error.";

  CLI::App* filter = app->add_subcommand(
      "filter", "Copy a time window and/or some topics of a recording to a new one that reads on its own");
  filter->add_option("in", o->file, "MCAP file")->required();
  filter->add_option("out", o->out, "Output MCAP file")->required();
  filter->add_option("--start", o->start, "Keep messages logged at or after this many seconds")
      ->check(non_negative());
  filter->add_option("--end", o->end, "Keep messages logged before this many seconds")->check(non_negative());
  auto* keep =
      filter
          ->add_option("--topics", o->topics,
                       "Keep only these topics, comma-separated; each as recorded (/rbsim/body_states) "
                       "or by its last name (body_states)")
          ->delimiter(',');
  filter->add_option("--exclude-topics", o->exclude_topics, "Leave these topics out, comma-separated")
      ->delimiter(',')
      ->excludes(keep);
  add_output_options(filter);
  filter->footer(
      std::string("With --start, the last message before the window of each kept latched topic (the "
                  "scene description, the markers: found by type) is kept too, with its own log "
                  "time, so the slice renders and checks on its own. Every kept topic is listed, "
                  "also one without messages in the window. Messages are written in log-time "
                  "order with their sequence numbers, schemas and channel metadata as recorded.\n") +
      rewrite_footer);

  CLI::App* merge =
      app->add_subcommand("merge", "Merge recordings into one, in log-time order (as 'mcap merge')");
  merge->add_option("files", o->files, "IN... OUT: two or more MCAP files, then the output")
      ->required()
      ->expected(3, -1);
  merge
      ->add_option("--namespaces", o->namespaces,
                   "One ROS namespace per input, comma-separated (\"/\": none), put before its topics: "
                   "/a,/b makes /a/rbsim/body_states and /b/rbsim/body_states")
      ->delimiter(',');
  add_output_options(merge);
  merge->footer(
      std::string("Equal log times keep the order of the inputs, then of each file. Identical "
                  "schemas and channels are written once. Two recordings of different scenes (their "
                  "scene descriptions differ on one topic) are refused unless --namespaces moves "
                  "them apart.\n") +
      rewrite_footer);

  CLI::App* compress = app->add_subcommand(
      "compress", "Re-chunk and re-compress a recording: the same messages, channels and schemas");
  compress->add_option("in", o->file, "MCAP file")->required();
  compress->add_option("out", o->out, "Output MCAP file")->required();
  add_output_options(compress);
  compress->footer(std::string("Messages in log-time order, as 'rbsim log filter' without a selection.\n") +
                   rewrite_footer);

  return {filter, merge, compress};
}

}  // namespace

Subcommand add_log_command(CLI::App& parent) {
  auto o = std::make_shared<LogOptions>();
  CLI::App* app = parent.add_subcommand("log",
                                        "Inspect, check, repair, export, print, filter, merge and "
                                        "re-compress MCAP recordings (rbsim run --record)");
  app->require_subcommand(1);
  app->footer("Run 'rbsim log <command> --help' for a command's options.");

  const InspectApps inspect = add_inspect_commands(app, o);
  const ReadApps read = add_read_commands(app, o);
  const RewriteApps rewrite = add_rewrite_commands(app, o);

  return {app, [o, inspect, read, rewrite]() -> int {
            if (inspect.info->parsed()) return info_command(*o);
            if (inspect.doctor->parsed()) return doctor_command(*o);
            if (inspect.recover->parsed()) return recover_command(*o);
            if (read.exp->parsed()) return export_command(*o);
            if (read.cat->parsed()) return cat_command(*o);
            if (rewrite.filter->parsed()) return filter_command(*o);
            if (rewrite.merge->parsed()) return merge_command(*o);
            if (rewrite.compress->parsed()) return compress_command(*o);
            return 1;
          }};
}

}  // namespace rbsim::cli
