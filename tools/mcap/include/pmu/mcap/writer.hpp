#pragma once
// An MCAP writer (https://mcap.dev/spec) for pmuctl's recordings: Schema and Channel records,
// Message records in uncompressed Chunks with their Message Indexes, and on close a Summary
// (schemas, channels, statistics, chunk indexes), Summary Offsets and the Footer.
//
// Crash safety: each chunk and the message indexes after it go to the sink in one write, and
// the sink passes them to the kernel at once. A process killed at any time leaves a file
// whose complete chunks a stream reader reads; a failed write (disk full) is cut off again,
// so the file never ends in half a record. A stream cannot be cut: after a failed write
// nothing more is written to it.
//
// Errors: nothing throws. A failed write makes the writer failed(): later calls do nothing
// and return false; error() is the errno. close() on a failed writer still tries to end the
// data with a DataEnd and an empty Footer, so readers that need a footer accept the file.
//
// Lifetime: `sink` must outlive the writer, which keeps a reference (McapRecording declares
// the OutputFile whose sink() it is before the writer, so it is destroyed after it).
// Not thread-safe: the caller serialises calls.

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "pmu/mcap/records.hpp"
#include "pmu/mcap/sink.hpp"

namespace pmu::mcap {

struct WriterOptions {
  std::string profile;                  // "" (no well-known profile)
  std::string library;                  // e.g. "pmuctl 0.1.0"
  std::size_t chunk_size = 256 * 1024;  // a chunk is written when its records reach this
};

class Writer {
 public:
  Writer(Sink& sink, WriterOptions options);
  Writer(const Writer&) = delete;
  Writer& operator=(const Writer&) = delete;

  // Magic and Header. False when the sink refused them.
  bool open();
  // Ids from 1. A schema and a channel go into the chunk being filled, so every chunk a
  // stream reader reaches has them before the messages that need them.
  std::uint16_t add_schema(const std::string& name, const std::string& encoding, const std::string& data);
  std::uint16_t add_channel(std::uint16_t schema_id, const std::string& topic, const std::string& message_encoding);
  // Times are ns since the Unix epoch. Writes the chunk when it is full.
  bool write(std::uint16_t channel_id, std::uint64_t log_time, std::uint64_t publish_time, const std::uint8_t* data,
             std::size_t size);
  // Writes the chunk being filled (if it holds anything): what was written so far survives a crash.
  bool flush();
  // The last chunk, DataEnd, Summary, Summary Offsets, Footer, magic. False on a write error;
  // then (disk full, say) the file still ends with DataEnd, a Footer without summary and the
  // magic right after its last complete chunk, in space reserved before every block.
  bool close();

  bool failed() const noexcept { return error_ != 0; }
  int error() const noexcept { return error_; }
  std::uint64_t bytes_written() const noexcept { return offset_; }
  std::uint64_t message_count() const noexcept { return stats_.message_count; }

 private:
  bool emit(const Bytes& block, bool data_section, bool reserve_ending = true);
  Bytes ending_without_summary() const;
  Bytes summary_and_footer();  // DataEnd, the summary section, its offsets, Footer, magic

  Sink& sink_;
  WriterOptions options_;
  int error_ = 0;
  bool torn_ = false;  // a failed write could not be cut off: the sink ends in part of a block
  bool opened_ = false;
  bool closed_ = false;
  std::uint64_t offset_ = 0;    // bytes the sink took
  std::uint32_t data_crc_ = 0;  // of every byte from the magic to the chunk before DataEnd
  std::vector<Schema> schemas_;
  std::vector<Channel> channels_;
  std::vector<std::uint32_t> sequences_;  // per channel id - 1
  std::vector<ChunkIndex> chunk_indexes_;
  Statistics stats_;
  std::map<std::uint16_t, std::uint64_t> channel_counts_;
  // The chunk being filled.
  Bytes records_;
  std::uint64_t chunk_start_ = 0;
  std::uint64_t chunk_end_ = 0;
  bool chunk_has_messages_ = false;
  std::map<std::uint16_t, std::vector<std::pair<std::uint64_t, std::uint64_t>>> index_;
};

}  // namespace pmu::mcap
