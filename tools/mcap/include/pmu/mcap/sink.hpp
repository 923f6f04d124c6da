#pragma once
// Where the writer's bytes go. A file (FileSink) or memory (MemorySink, for tests).
//
// write() takes a whole block (a chunk with its message indexes, or the summary and footer)
// and reports failure as an errno value, never by throwing; truncate() removes what a
// failed write left behind, so the file ends at the last complete block. reserve() claims
// space ahead of the end without writing it, so that the few bytes that end a recording
// still fit when the disk fills up (the writer reserves them before every block).

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace pmu::mcap {

class Sink {
 public:
  virtual ~Sink() = default;
  // 0, or the errno of the failure (ENOSPC, EIO, ...).
  virtual int write(const std::uint8_t* data, std::size_t size) = 0;
  virtual int truncate(std::uint64_t size) = 0;
  // Claims [offset, offset + length) so later writes there cannot fail for want of space.
  // 0, ENOSPC, or another errno; a sink that cannot reserve returns 0.
  virtual int reserve(std::uint64_t offset, std::uint64_t length) = 0;
};

class MemorySink final : public Sink {
 public:
  int write(const std::uint8_t* data, std::size_t size) override;
  int truncate(std::uint64_t size) override;
  int reserve(std::uint64_t offset, std::uint64_t length) override;
  std::vector<std::uint8_t> bytes;
  // Tests: the write that makes the total exceed this (and what was reserved) fails with
  // ENOSPC after a partial copy; so does a reservation past it. Space reserved stays usable
  // when the capacity is lowered later, as fallocate(2)'d blocks do when the disk fills.
  std::size_t capacity = static_cast<std::size_t>(-1);
  std::size_t reserved = 0;
};

// A file created (or truncated) for writing. Every write is flushed to the kernel at once:
// nothing is kept in a user-space buffer that a crash would lose.
class FileSink final : public Sink {
 public:
  FileSink() = default;
  ~FileSink() override;
  FileSink(const FileSink&) = delete;
  FileSink& operator=(const FileSink&) = delete;
  FileSink(FileSink&& o) noexcept;
  FileSink& operator=(FileSink&& o) noexcept;

  // 0, or the errno of open(2).
  int open(const std::string& path);
  int write(const std::uint8_t* data, std::size_t size) override;
  int truncate(std::uint64_t size) override;
  // fallocate(2) with FALLOC_FL_KEEP_SIZE: blocks past the end, the file's size unchanged.
  // On a file system without it, 0 and no reservation (the ending may then not fit).
  int reserve(std::uint64_t offset, std::uint64_t length) override;
  // fsync(2) then close(2); 0 or the errno.
  int close();
  bool is_open() const noexcept { return fd_ >= 0; }

 private:
  int fd_ = -1;
  bool can_reserve_ = true;
};

}  // namespace pmu::mcap
