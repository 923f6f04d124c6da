#include "pmu/mcap/records.hpp"

#include "pmu/mcap/crc32.hpp"

namespace pmu::mcap {
namespace {

template <class T>
void put(Bytes& out, T v) {
  for (std::size_t i = 0; i < sizeof(T); ++i)
    out.push_back(static_cast<std::uint8_t>(static_cast<std::uint64_t>(v) >> (8 * i)));
}

void put_string(Bytes& out, std::string_view s) {
  put<std::uint32_t>(out, static_cast<std::uint32_t>(s.size()));
  out.insert(out.end(), s.begin(), s.end());
}

// Writes the opcode and a length placeholder; the returned position is patched by end_record.
std::size_t begin_record(Bytes& out, Opcode op) {
  out.push_back(op);
  const std::size_t at = out.size();
  put<std::uint64_t>(out, 0);
  return at;
}

void end_record(Bytes& out, std::size_t at) {
  const std::uint64_t length = out.size() - at - 8;
  for (std::size_t i = 0; i < 8; ++i) out[at + i] = static_cast<std::uint8_t>(length >> (8 * i));
}

// A u32 byte-length prefix for a Map or Array, patched by end_prefixed.
std::size_t begin_prefixed(Bytes& out) {
  const std::size_t at = out.size();
  put<std::uint32_t>(out, 0);
  return at;
}

void end_prefixed(Bytes& out, std::size_t at) {
  const auto length = static_cast<std::uint32_t>(out.size() - at - 4);
  for (std::size_t i = 0; i < 4; ++i) out[at + i] = static_cast<std::uint8_t>(length >> (8 * i));
}

void put_u16_u64_map(Bytes& out, const std::vector<std::pair<std::uint16_t, std::uint64_t>>& m) {
  const auto at = begin_prefixed(out);
  for (const auto& [k, v] : m) {
    put<std::uint16_t>(out, k);
    put<std::uint64_t>(out, v);
  }
  end_prefixed(out, at);
}

}  // namespace

void append_header(Bytes& out, std::string_view profile, std::string_view library) {
  const auto at = begin_record(out, kHeader);
  put_string(out, profile);
  put_string(out, library);
  end_record(out, at);
}

void append_schema(Bytes& out, const Schema& s) {
  const auto at = begin_record(out, kSchema);
  put<std::uint16_t>(out, s.id);
  put_string(out, s.name);
  put_string(out, s.encoding);
  put_string(out, s.data);  // uint32 length-prefixed bytes: the same layout as a String
  end_record(out, at);
}

void append_channel(Bytes& out, const Channel& c) {
  const auto at = begin_record(out, kChannel);
  put<std::uint16_t>(out, c.id);
  put<std::uint16_t>(out, c.schema_id);
  put_string(out, c.topic);
  put_string(out, c.message_encoding);
  const auto map = begin_prefixed(out);
  for (const auto& [k, v] : c.metadata) {
    put_string(out, k);
    put_string(out, v);
  }
  end_prefixed(out, map);
  end_record(out, at);
}

void append_message(Bytes& out, std::uint16_t channel_id, std::uint32_t sequence, std::uint64_t log_time,
                    std::uint64_t publish_time, const std::uint8_t* data, std::size_t size) {
  const auto at = begin_record(out, kMessage);
  put<std::uint16_t>(out, channel_id);
  put<std::uint32_t>(out, sequence);
  put<std::uint64_t>(out, log_time);
  put<std::uint64_t>(out, publish_time);
  out.insert(out.end(), data, data + size);
  end_record(out, at);
}

void append_chunk(Bytes& out, std::uint64_t start_time, std::uint64_t end_time, const Bytes& records) {
  const auto at = begin_record(out, kChunk);
  put<std::uint64_t>(out, start_time);
  put<std::uint64_t>(out, end_time);
  put<std::uint64_t>(out, records.size());
  put<std::uint32_t>(out, crc32(0, records.data(), records.size()));
  put_string(out, "");
  put<std::uint64_t>(out, records.size());
  out.insert(out.end(), records.begin(), records.end());
  end_record(out, at);
}

void append_message_index(Bytes& out, std::uint16_t channel_id,
                          const std::vector<std::pair<std::uint64_t, std::uint64_t>>& entries) {
  const auto at = begin_record(out, kMessageIndex);
  put<std::uint16_t>(out, channel_id);
  const auto arr = begin_prefixed(out);
  for (const auto& [time, offset] : entries) {
    put<std::uint64_t>(out, time);
    put<std::uint64_t>(out, offset);
  }
  end_prefixed(out, arr);
  end_record(out, at);
}

void append_chunk_index(Bytes& out, const ChunkIndex& c) {
  const auto at = begin_record(out, kChunkIndex);
  put<std::uint64_t>(out, c.message_start_time);
  put<std::uint64_t>(out, c.message_end_time);
  put<std::uint64_t>(out, c.chunk_start_offset);
  put<std::uint64_t>(out, c.chunk_length);
  put_u16_u64_map(out, c.message_index_offsets);
  put<std::uint64_t>(out, c.message_index_length);
  put_string(out, c.compression);
  put<std::uint64_t>(out, c.compressed_size);
  put<std::uint64_t>(out, c.uncompressed_size);
  end_record(out, at);
}

void append_statistics(Bytes& out, const Statistics& s) {
  const auto at = begin_record(out, kStatistics);
  put<std::uint64_t>(out, s.message_count);
  put<std::uint16_t>(out, s.schema_count);
  put<std::uint32_t>(out, s.channel_count);
  put<std::uint32_t>(out, 0);  // attachments
  put<std::uint32_t>(out, 0);  // metadata
  put<std::uint32_t>(out, s.chunk_count);
  put<std::uint64_t>(out, s.message_start_time);
  put<std::uint64_t>(out, s.message_end_time);
  put_u16_u64_map(out, s.channel_message_counts);
  end_record(out, at);
}

void append_summary_offset(Bytes& out, std::uint8_t group_opcode, std::uint64_t group_start,
                           std::uint64_t group_length) {
  const auto at = begin_record(out, kSummaryOffset);
  out.push_back(group_opcode);
  put<std::uint64_t>(out, group_start);
  put<std::uint64_t>(out, group_length);
  end_record(out, at);
}

void append_data_end(Bytes& out, std::uint32_t data_section_crc) {
  const auto at = begin_record(out, kDataEnd);
  put<std::uint32_t>(out, data_section_crc);
  end_record(out, at);
}

void append_footer(Bytes& out, std::uint64_t summary_start, std::uint64_t summary_offset_start,
                   std::uint32_t summary_crc_so_far, bool with_crc) {
  const std::size_t begin = out.size();
  out.push_back(kFooter);
  put<std::uint64_t>(out, 8 + 8 + 4);  // fixed: the Footer is never extended
  put<std::uint64_t>(out, summary_start);
  put<std::uint64_t>(out, summary_offset_start);
  const std::uint32_t crc = with_crc ? crc32(summary_crc_so_far, out.data() + begin, out.size() - begin) : 0;
  put<std::uint32_t>(out, crc);
}

}  // namespace pmu::mcap
