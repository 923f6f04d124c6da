#include "pmuctl/record/mcap_recording.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>

namespace pmu::tools {

std::string human_bytes(std::uint64_t n) {
  char buf[32];
  if (n < 1000)
    std::snprintf(buf, sizeof buf, "%llu B", static_cast<unsigned long long>(n));
  else if (n < 1000000)
    std::snprintf(buf, sizeof buf, "%.1f kB", static_cast<double>(n) / 1e3);
  else
    std::snprintf(buf, sizeof buf, "%.1f MB", static_cast<double>(n) / 1e6);
  return buf;
}

std::string McapRecording::open(const std::string& path, const std::vector<const RecordedTopic*>& topics) {
  if (auto why = out_.open(path); !why.empty()) return why;
  writer_ =
      std::make_unique<pmu::mcap::Writer>(out_.sink(), pmu::mcap::WriterOptions{"", "pmuctl (pmu-dds)", 256 * 1024});
  if (!writer_->open()) return error();
  for (const auto* t : topics) add_topic(t);
  // The schemas and channels reach the file at once: a recording stopped before its first
  // chunk still says what it would have held.
  return writer_->flush() ? std::string() : error();
}

std::size_t McapRecording::add_topic(const RecordedTopic* t) {
  auto it = schemas_.find(t->schema());
  if (it == schemas_.end())
    it =
        schemas_.emplace(t->schema(), writer_->add_schema(t->schema(), t->schema_encoding(), std::string(t->idl))).first;
  channels_.push_back(writer_->add_channel(it->second, t->channel_name(), "cdr"));
  topics_.push_back(t);
  counts_.push_back(0);
  return topics_.size() - 1;
}

bool McapRecording::write(std::size_t topic, std::uint64_t time_ns, const std::uint8_t* data, std::size_t size) {
  if (!writer_ || topic >= channels_.size()) return false;
  const std::uint64_t log_ns = time_ns < log_start_ns_ ? log_start_ns_ : time_ns;
  if (!writer_->write(channels_[topic], log_ns, time_ns, data, size)) return false;
  ++counts_[topic];
  return true;
}

bool McapRecording::flush() { return writer_ && writer_->flush(); }

std::string McapRecording::close() {
  if (!writer_) return {};
  const bool was_failed = writer_->failed();
  const bool ok = writer_->close();
  std::string why = ok ? std::string() : error();
  if (const int e = out_.close(); e != 0 && why.empty()) why = "closing " + out_.name() + ": " + std::strerror(e);
  if (was_failed)
    why += std::string(out_.streaming() ? " (it got" : " (the file holds") + " the chunks written before it, " +
           human_bytes(writer_->bytes_written()) + ")";
  return why;
}

std::string McapRecording::commit() { return out_.commit(); }

void McapRecording::discard() { out_.discard(); }

std::string McapRecording::error() const {
  if (!writer_ || !writer_->failed()) return {};
  const int e = writer_->error();
  std::string s = "writing " + out_.name() + ": " + std::strerror(e);
  if (e == ENOSPC) s += " (disk full)";
  return s + " after " + human_bytes(writer_->bytes_written());
}

std::string McapRecording::progress() const {
  std::string s = std::to_string(messages()) + " messages, " + human_bytes(writer_ ? writer_->bytes_written() : 0);
  std::string per;
  for (std::size_t i = 0; i < topics_.size(); ++i) {
    if (counts_[i] == 0) continue;
    std::string_view name = topics_[i]->channel_name();
    if (name.substr(0, 4) == "pmu/") name.remove_prefix(4);
    per += (per.empty() ? "" : ", ") + std::string(name) + " " + std::to_string(counts_[i]);
  }
  return per.empty() ? s : s + " (" + per + ")";
}

}  // namespace pmu::tools
