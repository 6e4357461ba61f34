// rbsim log doctor, the statistics: the Statistics record against what the walk counted.
#include "doctor.hpp"

namespace rbsim::mcap_tools::detail {

void Doctor::check_statistics() {
  if (!statistics_) return;
  const mcap::Statistics& s = *statistics_;
  if (message_count_ > 0) {
    if (s.message_start_time != min_log_time_) {
      error(cat("Statistics has message start time ", s.message_start_time,
                ", but the minimum message start time is ", min_log_time_));
    }
    if (s.message_end_time != max_log_time_) {
      error(cat("Statistics has message end time ", s.message_end_time,
                ", but the maximum message end time is ", max_log_time_));
    }
  }
  if (s.message_count != message_count_) {
    error(cat("Statistics has message count ", s.message_count, ", but actual number of messages is ",
              message_count_));
  }
  for (const auto& [channel_id, count] : channel_message_counts_) {
    const auto it = s.channel_message_counts.find(channel_id);
    const std::uint64_t stated = it == s.channel_message_counts.end() ? 0 : it->second;
    if (stated != count) {
      error(cat("Statistics has message count ", stated, " for channel ", channel_id,
                ", but actual number of messages is ", count));
    }
  }
  for (const auto& [channel_id, stated] : s.channel_message_counts) {
    if (stated != 0 && channel_message_counts_.count(channel_id) == 0) {
      error(cat("Statistics has message count ", stated, " for channel ", channel_id,
                ", but the channel has no messages"));
    }
  }
  auto count = [&](const char* what, std::uint64_t stated, std::uint64_t actual) {
    if (stated != actual)
      error(cat("Statistics has ", what, " count ", stated, ", but the file has ", actual));
  };
  count("schema", s.schema_count, schemas_.size());
  count("channel", s.channel_count, channels_.size());
  count("chunk", s.chunk_count, chunks_.size());
  count("attachment", s.attachment_count, attachments_.size());
  count("metadata", s.metadata_count, metadata_.size());
}

}  // namespace rbsim::mcap_tools::detail
