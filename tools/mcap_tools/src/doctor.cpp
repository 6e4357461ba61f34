// rbsim log doctor: the checks of the official `mcap doctor` (go/cli/mcap/cmd/doctor.go) plus
// the ones it leaves out (data section and summary CRCs, message index entries that point at no
// message, chunk index message-index offsets and lengths, statistics counts of schemas, channels,
// chunks, attachments and metadata, summary offsets, attachment and metadata indexes).
//
// One pass over the file record by record, then the summary checks (stages: doctor.hpp). Every
// loop is bounded by the bytes it reads: the records are framed by mcap::RecordReader, which
// checks each length against the bytes that remain before anything is read or allocated.
#include "doctor.hpp"

#include "tools_util.hpp"

namespace rbsim::mcap_tools {

std::string DoctorReport::first_error() const {
  for (const DoctorFinding& f : findings) {
    if (f.error) return f.text;
  }
  return {};
}

namespace detail {

DoctorReport Doctor::run(const std::string& path) {
  auto source = open_input(path);
  if (!source) {
    error(source.error().message);
    return std::move(report_);
  }
  size_ = source.value()->size();
  if (walk(*source.value())) {
    check_footer_offsets();
    check_summary_offsets();
    check_chunk_indexes();
    check_statistics();
    check_attachment_indexes();
    check_metadata_indexes();
  }
  if (report_.findings.size() < report_.errors + report_.warnings) {
    report_.findings.push_back({false, cat(report_.errors + report_.warnings - report_.findings.size(),
                                           " further findings not shown")});
  }
  return std::move(report_);
}

}  // namespace detail

DoctorReport doctor(const std::string& path, const DoctorOptions& options) {
  return detail::Doctor(options).run(path);
}

}  // namespace rbsim::mcap_tools
