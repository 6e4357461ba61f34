// rbsim log doctor, one parsed record of the structure walk by type: where it may stand (data
// section or summary), duplicates, and what the later stages need of it.
#include <algorithm>
#include <variant>

#include "doctor.hpp"

namespace rbsim::mcap_tools::detail {

using mcap::opcode_name;

void Doctor::handle(const mcap::RecordView& view, mcap::Record& record) {
  std::visit([&](auto& r) { on(view, r); }, record);
}

void Doctor::data_only(const mcap::RecordView& view) {
  if (in_summary_) error(cat(opcode_name(view.opcode), " record", at_pos(), " is in the summary section"));
}

void Doctor::summary_only(const mcap::RecordView& view) {
  if (!in_summary_) {
    warn(cat(opcode_name(view.opcode), " record", at_pos(),
             " is in the data section (readers look for it in the summary)"));
  }
}

void Doctor::warn_messages_outside_chunks() {
  if (message_outside_chunk_ && !warned_outside_chunk_) {
    warned_outside_chunk_ = true;
    warn(
        "Message index in file has message records outside chunks. Indexed readers will miss these "
        "messages.");
  }
}

void Doctor::on(const mcap::RecordView&, const mcap::Header& h) {
  if (seen_header_ || pos_ != mcap::kMagicSize)
    error(cat("Header record", at_pos(), " is not the first record"));
  seen_header_ = true;
  if (h.library.empty()) {
    warn("Set the Header.library field to a value that identifies the software that produced the file.");
  }
  if (!h.profile.empty() && h.profile != "ros1" && h.profile != "ros2") {
    warn(cat("Header.profile field \"", h.profile, "\" is not a well-known profile."));
  }
}

void Doctor::on(const mcap::RecordView&, const mcap::Footer& footer) {
  footer_ = footer;
  if (!data_end_) error("Footer without a DataEnd record before it");
}

void Doctor::on(const mcap::RecordView&, const mcap::Schema& schema) {
  examine_schema(schema);
}

void Doctor::on(const mcap::RecordView&, const mcap::Channel& channel) {
  examine_channel(channel);
}

void Doctor::on(const mcap::RecordView& view, const mcap::Message& m) {
  data_only(view);
  message_outside_chunk_ = true;
  if (channels_.count(m.channel_id) == 0) {
    error(cat("Got a Message record for channel: ", m.channel_id, " before a channel info", at_pos(), "."));
  }
  if (m.log_time < last_message_time_) {
    error(cat("Message.log_time ", m.log_time, " on \"", topic_of(m.channel_id),
              "\" is less than the previous message record time ", last_message_time_, at_pos()));
  }
  last_message_time_ = m.log_time;
  min_log_time_ = std::min(min_log_time_, m.log_time);
  max_log_time_ = std::max(max_log_time_, m.log_time);
  ++message_count_;
  ++channel_message_counts_[m.channel_id];
}

void Doctor::on(const mcap::RecordView& view, mcap::Chunk& chunk) {
  data_only(view);
  PendingChunk p;
  p.chunk = std::move(chunk);
  p.offset = pos_;
  p.length = view.length;
  pending_ = std::move(p);
}

void Doctor::on(const mcap::RecordView& view, mcap::MessageIndex& mi) {
  data_only(view);
  warn_messages_outside_chunks();
  if (!pending_) {
    error(cat("Message index", at_pos(), " found but no chunk before it"));
  } else if (pending_->indexes.count(mi.channel_id) != 0) {
    warn(cat("Duplicate message index found for channel ", mi.channel_id, at_pos()));
  } else {
    pending_->index_offsets[mi.channel_id] = pos_;
    pending_->index_length += view.length;
    pending_->indexes.emplace(mi.channel_id, std::move(mi));
  }
}

void Doctor::on(const mcap::RecordView& view, mcap::ChunkIndex& ci) {
  summary_only(view);
  warn_messages_outside_chunks();
  if (chunk_indexes_.count(ci.chunk_start_offset) != 0) {
    error(cat("Multiple chunk indexes found for chunk at offset ", ci.chunk_start_offset));
  } else {
    chunk_indexes_.emplace(ci.chunk_start_offset, std::move(ci));
  }
}

void Doctor::on(const mcap::RecordView& view, const mcap::Attachment& a) {
  data_only(view);
  if (a.crc != 0) {
    // Attachment.crc covers the record's fields before it: log_time, create_time, name,
    // media_type and data, each string and the data with its length prefix.
    const std::size_t covered = 8 + 8 + 4 + a.name.size() + 4 + a.media_type.size() + 8 + a.data.size();
    const std::uint32_t crc = mcap::crc32(view.content.subspan(0, std::min(covered, view.content.size())));
    if (crc != a.crc) {
      error(cat("Attachment \"", a.name, "\"", at_pos(), ": invalid CRC: computed ", hex32(crc),
                ", Attachment.crc is ", hex32(a.crc)));
    }
  }
  attachments_[pos_] = {view.length, a.log_time, a.create_time, a.data.size(), a.name, a.media_type};
}

void Doctor::on(const mcap::RecordView& view, const mcap::AttachmentIndex& index) {
  summary_only(view);
  attachment_indexes_.emplace_back(pos_, index);
}

void Doctor::on(const mcap::RecordView& view, const mcap::Statistics& statistics) {
  summary_only(view);
  if (statistics_) error("File contains multiple Statistics records");
  statistics_ = statistics;
}

void Doctor::on(const mcap::RecordView& view, const mcap::Metadata& metadata) {
  data_only(view);
  metadata_[pos_] = {view.length, metadata.name};
}

void Doctor::on(const mcap::RecordView& view, const mcap::MetadataIndex& index) {
  summary_only(view);
  metadata_indexes_.emplace_back(pos_, index);
}

void Doctor::on(const mcap::RecordView&, const mcap::SummaryOffset& offset) {
  if (!in_summary_) error(cat("SummaryOffset record", at_pos(), " is in the data section"));
  summary_offsets_.emplace_back(pos_, offset);
}

void Doctor::on(const mcap::RecordView& view, const mcap::DataEnd& data_end) {
  if (data_end_) {
    error(cat("second DataEnd record", at_pos()));
    return;
  }
  data_end_ = data_end;
  summary_begin_ = pos_ + view.length;
  in_summary_ = true;
  if (data_end_->data_section_crc != 0 && data_end_->data_section_crc != data_crc_) {
    error(cat("data section CRC mismatch: computed ", hex32(data_crc_), ", DataEnd.data_section_crc is ",
              hex32(data_end_->data_section_crc)));
  }
}

void Doctor::examine_schema(const mcap::Schema& schema) {
  if (schema.encoding.empty()) {
    if (schema.data.empty()) {
      warn(cat("Schema with ID: ", schema.id, ", Name: \"", schema.name,
               "\" has empty Encoding and Data fields"));
    } else {
      error(cat("Schema with ID: ", schema.id, " has empty Encoding but Data contains ", schema.data.size(),
                " bytes"));
    }
  }
  if (schema.id == 0) error("Schema.ID 0 is reserved. Do not make Schema records with ID 0.");
  const auto it = schemas_.find(schema.id);
  const mcap::Schema* previous = it == schemas_.end() ? nullptr : &it->second;
  if (previous != nullptr) {
    if (schema.name != previous->name) {
      error(cat("Two schema records with same ID ", schema.id, " but different names (\"", schema.name,
                "\" != \"", previous->name, "\")"));
    }
    if (schema.encoding != previous->encoding) {
      error(cat("Two schema records with same ID ", schema.id, " but different encodings (\"",
                schema.encoding, "\" != \"", previous->encoding, "\")"));
    }
    if (schema.data != previous->data) {
      error(cat("Two schema records with different data present with same ID ", schema.id));
    }
  }
  if (in_summary_) {
    if (previous == nullptr)
      error(cat("Schema with id ", schema.id, " in summary section does not exist in data section"));
    summary_schema_ids_.insert(schema.id);
  } else {
    if (previous != nullptr) warn(cat("Duplicate schema records in data section with ID ", schema.id));
    schemas_.insert_or_assign(schema.id, schema);
  }
}

void Doctor::examine_channel(const mcap::Channel& channel) {
  const auto it = channels_.find(channel.id);
  const mcap::Channel* previous = it == channels_.end() ? nullptr : &it->second;
  if (previous != nullptr) {
    if (channel.schema_id != previous->schema_id) {
      error(cat("Two channel records with same ID ", channel.id, " but different schema IDs (",
                channel.schema_id, " != ", previous->schema_id, ")"));
    }
    if (channel.topic != previous->topic) {
      error(cat("Two channel records with same ID ", channel.id, " but different topics (\"", channel.topic,
                "\" != \"", previous->topic, "\")"));
    }
    if (channel.message_encoding != previous->message_encoding) {
      error(cat("Two channel records with same ID ", channel.id, " but different message encodings (\"",
                channel.message_encoding, "\" != \"", previous->message_encoding, "\")"));
    }
    if (channel.metadata != previous->metadata) {
      error(cat("Two channel records with different metadata present with same ID ", channel.id));
    }
  }
  if (in_summary_) {
    if (previous == nullptr)
      error(cat("Channel with ID ", channel.id, " in summary section does not exist in data section"));
    summary_channel_ids_.insert(channel.id);
  } else {
    if (previous != nullptr) warn(cat("Duplicate channel records in data section with ID ", channel.id));
    channels_.insert_or_assign(channel.id, channel);
  }
  if (channel.schema_id != 0 && schemas_.count(channel.schema_id) == 0) {
    error(cat("Encountered Channel (", channel.id, ") with unknown Schema (", channel.schema_id, ")"));
  }
}

}  // namespace rbsim::mcap_tools::detail
