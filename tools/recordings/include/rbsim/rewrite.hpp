// `rbsim log filter | merge | compress`: a new recording written from one or more recordings,
// read through recordings::Recording and written through mcap::Writer (one path for all three: a
// selection of messages from some inputs, in log-time order, into one AtomicFile).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "rbsim/mcap.hpp"

namespace rbsim::recordings {

// How the output is chunked and compressed.
struct OutputOptions {
  mcap::Compression compression = mcap::Compression::Zstd;
  std::uint64_t chunk_size = 1u << 20;  // uncompressed bytes after which a chunk is written
};

// What a rewrite wrote.
struct RewriteReport {
  std::uint64_t messages = 0;  // messages written (latched ones included)
  std::uint64_t latched = 0;   // of those: latched messages from before a window's start
  std::uint64_t channels = 0, schemas = 0;
  std::uint64_t copied_chunks = 0;  // chunks copied whole, as stored (filter)
  std::vector<std::string> topics;  // the output's topics, in channel order (a topic once)
  // "wrote OUT: 1,234 messages (2 latched from before the window) on 7 topics, 7 channels, 7
  // schemas; 12 chunks copied whole"
  std::string summary(const std::string& out) const;
};

struct FilterOptions {
  // Topics to keep (empty: every topic), or to leave out; each as recorded ("/rbsim/body_states")
  // or by its last name part(s) ("body_states"). A name that matches no channel is an error.
  std::vector<std::string> topics, exclude_topics;
  // The log-time window in seconds: start inclusive, end exclusive. With a start, the last
  // message before it of every kept latched topic (msgs::TopicSpec::latched(): the scene
  // description, the markers; found by type) is kept too, with its own log time, so the slice
  // reads, renders and checks on its own.
  std::optional<double> start, end;
  OutputOptions output;
};

// Writes the messages of `in` that `options` selects to `out` (under a temporary name, renamed into
// place), in log-time order (equal times in file order). Every kept channel is listed, also one
// with no message in the window; each with its id, schema, metadata and sequence numbers as
// recorded, and the input's profile. A chunk inside the window whose channels are all kept, whose
// compression is the output's and whose time range no other chunk's crosses is copied as stored
// (its CRC checked on a second thread), not decompressed and compressed again; chunk_size applies
// to the chunks written anew. Errors name the file and the rule: unreadable or corrupt input, an
// unknown topic, both `topics` and `exclude_topics`, an end before the start.
[[nodiscard]] Result<RewriteReport> filter(const std::string& in, const std::string& out,
                                           const FilterOptions& options);

// Every message of `in` re-chunked and compressed as `output` says: the same messages, channels
// and schemas (filter() without a selection).
[[nodiscard]] Result<RewriteReport> compress(const std::string& in, const std::string& out,
                                             const OutputOptions& output);

struct MergeOptions {
  // Empty, or one ROS namespace per input ("/a"; "/" for none) put before each of its topics
  // ("/a/rbsim/body_states"), to move recordings of different scenes apart.
  std::vector<std::string> namespaces;
  OutputOptions output;
};

// Writes every message of `inputs` to `out` in log-time order; equal times in the order of
// `inputs`, then of each file. Identical schemas, and identical channels (topic, encoding, schema,
// metadata), are written once. Two inputs whose scene descriptions (found by type) share a topic
// but differ record different scenes: refused, naming both files and the topic, unless
// `namespaces` moves them apart. The profile is the first input's.
[[nodiscard]] Result<RewriteReport> merge(const std::vector<std::string>& inputs, const std::string& out,
                                          const MergeOptions& options);

}  // namespace rbsim::recordings
