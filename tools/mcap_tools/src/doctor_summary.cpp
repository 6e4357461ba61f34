// rbsim log doctor, the summary and index checks: the Footer's offsets, the summary offset
// groups, chunk indexes against the chunks, attachment and metadata indexes against their records.
#include <algorithm>

#include "doctor.hpp"

namespace rbsim::mcap_tools::detail {

using mcap::opcode_name;

void Doctor::check_footer_offsets() {
  const mcap::Footer& footer = *footer_;
  if (!data_end_) return;
  // Summary section: records between DataEnd and the summary offset section.
  std::uint64_t offsets_start = 0;  // first SummaryOffset record
  bool summary_records = false;
  for (const SummaryRecord& r : summary_records_) {
    if (r.opcode == mcap::opcode_of<mcap::SummaryOffset>()) {
      if (offsets_start == 0) offsets_start = r.offset;
    } else if (offsets_start != 0) {
      error(
          cat(opcode_name(r.opcode), " record at offset ", r.offset, " follows the summary offset section"));
    } else {
      summary_records = true;
    }
  }
  if (footer.summary_start != 0) {
    if (!summary_records) {
      error(cat("Footer.summary_start is ", footer.summary_start, ", but the file has no summary section"));
    } else if (footer.summary_start != summary_begin_) {
      error(cat("Footer.summary_start is ", footer.summary_start, ", but the summary section starts at ",
                summary_begin_));
    }
  } else if (summary_records) {
    warn(cat("the file has a summary section at offset ", summary_begin_,
             " but Footer.summary_start is 0: readers will not use it"));
  }
  if (footer.summary_offset_start != 0) {
    if (offsets_start == 0) {
      error(cat("Footer.summary_offset_start is ", footer.summary_offset_start,
                ", but the file has no SummaryOffset records"));
    } else if (footer.summary_offset_start != offsets_start) {
      error(cat("Footer.summary_offset_start is ", footer.summary_offset_start,
                ", but the summary offset section starts at ", offsets_start));
    }
  } else if (offsets_start != 0) {
    warn(cat("the file has SummaryOffset records at offset ", offsets_start,
             " but Footer.summary_offset_start is 0"));
  }
}

void Doctor::check_summary_offsets() {
  std::set<std::uint8_t> seen;
  for (const auto& [at, so] : summary_offsets_) {
    const std::string name = opcode_name(so.group_opcode);
    const std::string where = cat("SummaryOffset at offset ", at, " (", name, " group)");
    if (!seen.insert(so.group_opcode).second) {
      error(cat(where, ": a second summary offset for the same opcode"));
      continue;
    }
    auto it = std::find_if(summary_records_.begin(), summary_records_.end(),
                           [&](const SummaryRecord& r) { return r.offset == so.group_start; });
    if (it == summary_records_.end()) {
      error(cat(where, ": group_start ", so.group_start, " is not the start of a summary record"));
      continue;
    }
    std::uint64_t covered = 0, in_group = 0;
    bool bad = false;
    for (; it != summary_records_.end() && covered < so.group_length; ++it) {
      if (it->opcode != so.group_opcode) {
        error(cat(where, ": the group holds a ", opcode_name(it->opcode), " record at offset ", it->offset));
        bad = true;
        break;
      }
      covered += it->length;
      ++in_group;
    }
    if (bad) continue;
    if (covered != so.group_length) {
      error(cat(where, ": group_length ", so.group_length,
                " does not end at a record boundary (records cover ", covered, " bytes)"));
      continue;
    }
    const auto total = static_cast<std::uint64_t>(
        std::count_if(summary_records_.begin(), summary_records_.end(),
                      [&](const SummaryRecord& r) { return r.opcode == so.group_opcode; }));
    if (total != in_group) {
      error(cat(where, ": the group holds ", in_group, " of the ", total, " ", name,
                " records in the summary"));
    }
  }
}

void Doctor::check_chunk_indexes() {
  for (const auto& [offset, ci] : chunk_indexes_) {
    const auto found = chunks_.find(offset);
    if (found == chunks_.end()) {
      error(cat("Chunk index points to offset ", offset, ", where there is no Chunk record"));
      continue;
    }
    check_chunk_index(ci, found->second);
  }
  if (!chunk_indexes_.empty()) {
    for (const auto& [offset, chunk] : chunks_) {
      if (chunk_indexes_.count(offset) == 0) {
        error(cat("Chunk at offset ", offset, " has no chunk index: indexed readers will miss its messages"));
      }
    }
  }
}

// One chunk index against the chunk at its offset.
void Doctor::check_chunk_index(const mcap::ChunkIndex& ci, const ChunkInfo& chunk) {
  const std::uint64_t offset = chunk.offset;
  const std::string where = cat("Chunk index for offset ", offset);
  for (std::uint16_t id : chunk.channels) {
    if (summary_channel_ids_.count(id) == 0) {
      error(cat("Indexed chunk at offset ", offset, " contains messages referencing channel (", id,
                ") not duplicated in summary section"));
    }
    const auto channel = channels_.find(id);
    if (channel == channels_.end()) continue;  // reported where the message was read
    if (channel->second.schema_id != 0 && summary_schema_ids_.count(channel->second.schema_id) == 0) {
      error(cat("Indexed chunk at offset ", offset, " contains messages referencing schema (",
                channel->second.schema_id, ") not duplicated in summary section"));
    }
  }
  if (ci.chunk_length != chunk.length) {
    error(cat("Chunk index ", offset, " length mismatch: ", ci.chunk_length, " vs ", chunk.length, "."));
    return;
  }
  if (chunk.start != ci.message_start_time) {
    error(cat("Chunk at offset ", offset, " has message start time ", chunk.start,
              ", but its chunk index has message start time ", ci.message_start_time));
  }
  if (chunk.end != ci.message_end_time) {
    error(cat("Chunk at offset ", offset, " has message end time ", chunk.end,
              ", but its chunk index has message end time ", ci.message_end_time));
  }
  if (chunk.compression != ci.compression) {
    error(cat("Chunk at offset ", offset, " has compression \"", chunk.compression,
              "\", but its chunk index has compression \"", ci.compression, "\""));
  }
  if (chunk.compressed_size != ci.compressed_size) {
    error(cat("Chunk at offset ", offset, " has data length ", chunk.compressed_size,
              ", but its chunk index has compressed size ", ci.compressed_size));
  }
  if (chunk.uncompressed_size != ci.uncompressed_size) {
    error(cat("Chunk at offset ", offset, " has uncompressed size ", chunk.uncompressed_size,
              ", but its chunk index has uncompressed size ", ci.uncompressed_size));
  }
  for (const auto& [channel_id, index_offset] : ci.message_index_offsets) {
    const auto real = chunk.index_offsets.find(channel_id);
    if (real == chunk.index_offsets.end()) {
      error(cat(where, ": message index offset ", index_offset, " for channel ", channel_id,
                ", but the chunk has no MessageIndex record for that channel"));
    } else if (real->second != index_offset) {
      error(cat(where, ": message index offset for channel ", channel_id, " is ", index_offset,
                ", but its MessageIndex record is at offset ", real->second));
    }
  }
  for (const auto& [channel_id, index_offset] : chunk.index_offsets) {
    if (ci.message_index_offsets.count(channel_id) == 0) {
      error(cat(where, ": no message index offset for channel ", channel_id,
                " (its MessageIndex record is at offset ", index_offset, ")"));
    }
  }
  if (!ci.message_index_offsets.empty() && ci.message_index_length != chunk.index_length) {
    error(cat(where, ": message_index_length is ", ci.message_index_length,
              ", but the chunk's MessageIndex records take ", chunk.index_length, " bytes"));
  }
}

void Doctor::check_attachment_indexes() {
  std::set<std::uint64_t> indexed;
  for (const auto& [at, ai] : attachment_indexes_) {
    const std::string where = cat("AttachmentIndex at offset ", at);
    const auto it = attachments_.find(ai.offset);
    if (it == attachments_.end()) {
      error(cat(where, " points to offset ", ai.offset, ", where there is no Attachment record"));
      continue;
    }
    indexed.insert(ai.offset);
    const AttachmentSeen& a = it->second;
    if (ai.length != a.length)
      error(cat(where, ": length ", ai.length, ", but the Attachment record takes ", a.length));
    if (ai.log_time != a.log_time)
      error(cat(where, ": log_time ", ai.log_time, ", but the attachment has ", a.log_time));
    if (ai.create_time != a.create_time) {
      error(cat(where, ": create_time ", ai.create_time, ", but the attachment has ", a.create_time));
    }
    if (ai.data_size != a.data_size)
      error(cat(where, ": data_size ", ai.data_size, ", but the attachment has ", a.data_size));
    if (ai.name != a.name)
      error(cat(where, ": name \"", ai.name, "\", but the attachment is \"", a.name, "\""));
    if (ai.media_type != a.media_type) {
      error(
          cat(where, ": media_type \"", ai.media_type, "\", but the attachment has \"", a.media_type, "\""));
    }
  }
  if (!attachment_indexes_.empty()) {
    for (const auto& [offset, a] : attachments_) {
      if (indexed.count(offset) == 0)
        error(cat("Attachment \"", a.name, "\" at offset ", offset, " has no attachment index"));
    }
  }
}

void Doctor::check_metadata_indexes() {
  std::set<std::uint64_t> indexed;
  for (const auto& [at, mi] : metadata_indexes_) {
    const std::string where = cat("MetadataIndex at offset ", at);
    const auto it = metadata_.find(mi.offset);
    if (it == metadata_.end()) {
      error(cat(where, " points to offset ", mi.offset, ", where there is no Metadata record"));
      continue;
    }
    indexed.insert(mi.offset);
    if (mi.length != it->second.first) {
      error(cat(where, ": length ", mi.length, ", but the Metadata record takes ", it->second.first));
    }
    if (mi.name != it->second.second) {
      error(cat(where, ": name \"", mi.name, "\", but the metadata is \"", it->second.second, "\""));
    }
  }
  if (!metadata_indexes_.empty()) {
    for (const auto& [offset, m] : metadata_) {
      if (indexed.count(offset) == 0)
        error(cat("Metadata \"", m.second, "\" at offset ", offset, " has no metadata index"));
    }
  }
}

}  // namespace rbsim::mcap_tools::detail
