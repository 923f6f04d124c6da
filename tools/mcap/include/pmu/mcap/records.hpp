#pragma once
// MCAP records as bytes (https://mcap.dev/spec, major version 0): each record is
// <opcode u8><content length u64><content>, integers little-endian, a String is a u32 byte
// length and the bytes, a Map or Array a u32 byte length and the entries.
//
// Only the records pmuctl writes are here. The functions append to a byte buffer and cannot
// fail; the writer (writer.hpp) decides where the bytes go.

#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace pmu::mcap {

using Bytes = std::vector<std::uint8_t>;

// 0x89 'M' 'C' 'A' 'P' '0' '\r' '\n': first and last 8 bytes of every file.
inline constexpr std::uint8_t kMagic[8] = {0x89, 'M', 'C', 'A', 'P', 0x30, '\r', '\n'};

enum Opcode : std::uint8_t {
  kHeader = 0x01,
  kFooter = 0x02,
  kSchema = 0x03,
  kChannel = 0x04,
  kMessage = 0x05,
  kChunk = 0x06,
  kMessageIndex = 0x07,
  kChunkIndex = 0x08,
  kStatistics = 0x0B,
  kSummaryOffset = 0x0E,
  kDataEnd = 0x0F,
};

struct Schema {
  std::uint16_t id = 0;  // never 0: 0 means "no schema"
  std::string name;
  std::string encoding;
  std::string data;
};

struct Channel {
  std::uint16_t id = 0;
  std::uint16_t schema_id = 0;
  std::string topic;
  std::string message_encoding;
  std::vector<std::pair<std::string, std::string>> metadata;
};

struct ChunkIndex {
  std::uint64_t message_start_time = 0;
  std::uint64_t message_end_time = 0;
  std::uint64_t chunk_start_offset = 0;
  std::uint64_t chunk_length = 0;  // the whole Chunk record, opcode and length included
  std::vector<std::pair<std::uint16_t, std::uint64_t>> message_index_offsets;
  std::uint64_t message_index_length = 0;
  std::string compression;
  std::uint64_t compressed_size = 0;
  std::uint64_t uncompressed_size = 0;
};

struct Statistics {
  std::uint64_t message_count = 0;
  std::uint16_t schema_count = 0;
  std::uint32_t channel_count = 0;
  std::uint32_t chunk_count = 0;
  std::uint64_t message_start_time = 0;
  std::uint64_t message_end_time = 0;
  std::vector<std::pair<std::uint16_t, std::uint64_t>> channel_message_counts;
};

// Appends one record each.
void append_header(Bytes& out, std::string_view profile, std::string_view library);
void append_schema(Bytes& out, const Schema& s);
void append_channel(Bytes& out, const Channel& c);
void append_message(Bytes& out, std::uint16_t channel_id, std::uint32_t sequence, std::uint64_t log_time,
                    std::uint64_t publish_time, const std::uint8_t* data, std::size_t size);
// An uncompressed chunk around `records` (whole records, as append_* made them).
void append_chunk(Bytes& out, std::uint64_t start_time, std::uint64_t end_time, const Bytes& records);
// (log time, offset of the Message record within the chunk's records).
void append_message_index(Bytes& out, std::uint16_t channel_id,
                          const std::vector<std::pair<std::uint64_t, std::uint64_t>>& entries);
void append_chunk_index(Bytes& out, const ChunkIndex& c);
void append_statistics(Bytes& out, const Statistics& s);
void append_summary_offset(Bytes& out, std::uint8_t group_opcode, std::uint64_t group_start,
                           std::uint64_t group_length);
void append_data_end(Bytes& out, std::uint32_t data_section_crc);
// The Footer's summary_crc covers the summary up to and including summary_offset_start, so
// the caller passes the CRC of the summary sections so far; the footer adds its own part.
void append_footer(Bytes& out, std::uint64_t summary_start, std::uint64_t summary_offset_start,
                   std::uint32_t summary_crc_so_far, bool with_crc);

}  // namespace pmu::mcap
