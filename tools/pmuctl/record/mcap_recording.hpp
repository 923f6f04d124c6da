#pragma once
// An MCAP file of contract topics (mcap_topics.hpp) for `pmuctl record` and `decode --mcap`:
// the file, its schemas and channels, per-topic counts for the progress line, and errors in
// words ("writing rec.mcap: No space left on device after 1.2 MB"). Where the bytes go, and
// what is never overwritten, is pmu::mcap::OutputFile's (output_file.hpp): a regular file is
// written beside its name and renamed onto it by commit(); a FIFO, a character device and
// "-" (standard output) are written in place.
// No DDS: samples arrive as CDR bytes. Not thread-safe (record serialises calls).

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "pmu/mcap/output_file.hpp"
#include "pmu/mcap/writer.hpp"
#include "pmuctl/record/mcap_topics.hpp"

namespace pmu::tools {

class McapRecording {
 public:
  // Opens `path` (OutputFile) and writes the header, one schema per type and one channel
  // per topic. "" on success, else what failed and where; created() then tells whether the
  // output was refused (nothing made) or failed once written to (disk full).
  std::string open(const std::string& path, const std::vector<const RecordedTopic*>& topics);

  // Log times from `start_ns` on (record: when the recording started). A message older than
  // that (state published before, which DDS gives a late reader) is logged at `start_ns`, so a
  // player's timeline starts with the recording, not hours before; its publish time stays its
  // own. Without it (decode --mcap) log time = publish time.
  void start_log_times_at(std::uint64_t start_ns) { log_start_ns_ = start_ns; }
  // One more topic, while recording (a ROS 2 topic discovery found): its schema (unless a
  // topic of its type has it) and channel go into the chunk being filled, before its first
  // message. Its index for write() is the number of topics before it.
  std::size_t add_topic(const RecordedTopic* topic);

  // `topic`: index into open()'s list, then add_topic()'s. `time_ns`: since the Unix epoch, the message's publish
  // time (its source time), and its log time unless before start_log_times_at's. False once
  // the file cannot be written (error()).
  bool write(std::size_t topic, std::uint64_t time_ns, const std::uint8_t* data, std::size_t size);
  // The chunk so far to the file, so a crash keeps it.
  bool flush();
  // Summary and footer, then the file closed; "" or what failed. After a write error, ends
  // the file as well as it can.
  std::string close();
  // After close(): a regular file renamed onto its name. "" or what failed (the file then
  // stays under its temporary name, which the message gives).
  std::string commit();
  // Closes and removes what open() created: only its own temporary file; a stream keeps
  // what it got.
  void discard();

  bool failed() const { return writer_ && writer_->failed(); }
  bool created() const { return writer_ != nullptr; }
  bool streaming() const { return out_.streaming(); }
  // What the operator named ("rec.mcap", "standard output").
  const std::string& name() const { return out_.name(); }
  // Bytes written so far; after close(), the size of what was written.
  std::uint64_t bytes() const { return writer_ ? writer_->bytes_written() : 0; }
  std::string error() const;     // "" or what failed and where
  std::string progress() const;  // "1234 messages, 56.7 kB (voltages 200, currents 200, ...)"
  std::uint64_t messages() const { return writer_ ? writer_->message_count() : 0; }

 private:
  pmu::mcap::OutputFile out_;  // before writer_, which writes to its sink: destroyed after it
  std::unique_ptr<pmu::mcap::Writer> writer_;
  std::vector<const RecordedTopic*> topics_;
  std::vector<std::uint16_t> channels_;
  std::vector<std::uint64_t> counts_;
  std::uint64_t log_start_ns_ = 0;
  std::map<std::string, std::uint16_t> schemas_;  // by schema name: topics of one type share it
};

// "56.7 kB"
std::string human_bytes(std::uint64_t n);

}  // namespace pmu::tools
