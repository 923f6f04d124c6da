#include "pmu/mcap/writer.hpp"

#include <algorithm>
#include <tuple>

#include "pmu/mcap/crc32.hpp"

namespace pmu::mcap {

Writer::Writer(Sink& sink, WriterOptions options) : sink_(sink), options_(std::move(options)) {}

bool Writer::emit(const Bytes& block, bool data_section, bool reserve_ending) {
  if (error_ != 0) return false;
  // The block and, after it, room for the ending: when the disk fills, the failure comes here,
  // before anything is written, and the room reserved with the previous block is still there.
  const std::uint64_t ending = reserve_ending ? ending_without_summary().size() : 0;  // 50 bytes
  if (const int e = reserve_ending ? sink_.reserve(offset_, block.size() + ending) : 0; e != 0) {
    error_ = e;
    return false;
  }
  if (const int e = sink_.write(block.data(), block.size()); e != 0) {
    error_ = e;
    if (sink_.truncate(offset_) != 0)
      torn_ = true;  // the file ends at the last complete block again
    else if (reserve_ending)
      sink_.reserve(offset_, ending);  // truncating freed what was reserved past the end
    return false;
  }
  if (data_section) data_crc_ = crc32(data_crc_, block.data(), block.size());
  offset_ += block.size();
  return true;
}

bool Writer::open() {
  Bytes b(std::begin(kMagic), std::end(kMagic));
  append_header(b, options_.profile, options_.library);
  opened_ = emit(b, true);
  return opened_;
}

std::uint16_t Writer::add_schema(const std::string& name, const std::string& encoding, const std::string& data) {
  Schema s{static_cast<std::uint16_t>(schemas_.size() + 1), name, encoding, data};
  append_schema(records_, s);
  schemas_.push_back(std::move(s));
  return schemas_.back().id;
}

std::uint16_t Writer::add_channel(std::uint16_t schema_id, const std::string& topic,
                                  const std::string& message_encoding) {
  Channel c{static_cast<std::uint16_t>(channels_.size() + 1), schema_id, topic, message_encoding, {}};
  append_channel(records_, c);
  channels_.push_back(std::move(c));
  sequences_.push_back(0);
  return channels_.back().id;
}

bool Writer::write(std::uint16_t channel_id, std::uint64_t log_time, std::uint64_t publish_time,
                   const std::uint8_t* data, std::size_t size) {
  if (error_ != 0 || closed_ || channel_id == 0 || channel_id > channels_.size()) return false;
  if (!chunk_has_messages_) {
    chunk_start_ = chunk_end_ = log_time;
    chunk_has_messages_ = true;
  }
  chunk_start_ = std::min(chunk_start_, log_time);
  chunk_end_ = std::max(chunk_end_, log_time);
  index_[channel_id].emplace_back(log_time, records_.size());
  append_message(records_, channel_id, sequences_[channel_id - 1u]++, log_time, publish_time, data, size);
  if (stats_.message_count == 0) stats_.message_start_time = stats_.message_end_time = log_time;
  ++stats_.message_count;
  stats_.message_start_time = std::min(stats_.message_start_time, log_time);
  stats_.message_end_time = std::max(stats_.message_end_time, log_time);
  ++channel_counts_[channel_id];
  return records_.size() < options_.chunk_size || flush();
}

bool Writer::flush() {
  if (error_ != 0) return false;
  if (records_.empty()) return true;
  ChunkIndex ci;
  ci.message_start_time = chunk_has_messages_ ? chunk_start_ : 0;
  ci.message_end_time = chunk_has_messages_ ? chunk_end_ : 0;
  ci.chunk_start_offset = offset_;
  Bytes block;
  block.reserve(records_.size() + 128);
  append_chunk(block, ci.message_start_time, ci.message_end_time, records_);
  ci.chunk_length = block.size();
  for (const auto& [channel, entries] : index_) {
    ci.message_index_offsets.emplace_back(channel, offset_ + block.size());
    append_message_index(block, channel, entries);
  }
  ci.message_index_length = block.size() - ci.chunk_length;
  ci.compressed_size = ci.uncompressed_size = records_.size();
  if (!emit(block, true)) return false;
  chunk_indexes_.push_back(std::move(ci));
  ++stats_.chunk_count;
  records_.clear();
  index_.clear();
  chunk_has_messages_ = false;
  return true;
}

Bytes Writer::ending_without_summary() const {
  Bytes end;
  append_data_end(end, data_crc_);
  append_footer(end, 0, 0, 0, false);
  end.insert(end.end(), std::begin(kMagic), std::end(kMagic));
  return end;
}

bool Writer::close() {
  if (closed_) return error_ == 0;
  closed_ = true;
  if (!opened_) return false;
  if (error_ == 0 && flush()) {
    Bytes summary = summary_and_footer();
    if (emit(summary, false)) return true;
  }
  // Disk full or the like: end the data properly so the complete chunks stay readable by
  // every reader, without a summary (it did not fit).
  // Not after part of a block that could not be cut off (a stream): the ending would follow
  // half a record, and a reader would take its bytes for the record's.
  const int first = error_;
  error_ = 0;
  if (!torn_) emit(ending_without_summary(), false, false);  // into the room reserved with the last block
  error_ = first;
  return false;
}

Bytes Writer::summary_and_footer() {
  Bytes b;
  append_data_end(b, data_crc_);
  const std::uint64_t summary_start = offset_ + b.size();
  const std::size_t summary_at = b.size();
  std::vector<std::tuple<std::uint8_t, std::uint64_t, std::uint64_t>> groups;
  auto group = [&](std::uint8_t op, auto&& append_all) {
    const std::size_t begin = b.size();
    append_all();
    if (b.size() > begin) groups.emplace_back(op, offset_ + begin, b.size() - begin);
  };
  group(kSchema, [&] {
    for (const auto& s : schemas_) append_schema(b, s);
  });
  group(kChannel, [&] {
    for (const auto& c : channels_) append_channel(b, c);
  });
  group(kStatistics, [&] {
    stats_.schema_count = static_cast<std::uint16_t>(schemas_.size());
    stats_.channel_count = static_cast<std::uint32_t>(channels_.size());
    stats_.channel_message_counts.assign(channel_counts_.begin(), channel_counts_.end());
    append_statistics(b, stats_);
  });
  group(kChunkIndex, [&] {
    for (const auto& c : chunk_indexes_) append_chunk_index(b, c);
  });
  const std::uint64_t summary_offset_start = offset_ + b.size();
  for (const auto& [op, start, length] : groups) append_summary_offset(b, op, start, length);
  const std::uint32_t crc = crc32(0, b.data() + summary_at, b.size() - summary_at);
  append_footer(b, summary_start, summary_offset_start, crc, true);
  b.insert(b.end(), std::begin(kMagic), std::end(kMagic));
  return b;
}

}  // namespace pmu::mcap
