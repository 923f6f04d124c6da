#pragma once
// Where the writer's bytes go. A file (FileSink) or memory (MemorySink, for tests).
//
// write() takes a whole block (a chunk with its message indexes, or the summary and footer)
// and reports failure as an errno value, never by throwing; truncate() removes what a
// failed write left behind, so the file ends at the last complete block. reserve() claims
// space ahead of the end without writing it, so that the few bytes that end a recording
// still fit when the disk fills up (the writer reserves them before every block).
// A stream (a pipe, a FIFO, a character device) can do neither: truncate() fails there and
// reserve() does nothing.

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
  // Tests: behave as a stream (truncate() fails with ESPIPE, reserve() claims nothing).
  bool stream = false;
};

// A file descriptor written from where it stands. Every write is flushed to the kernel at
// once: nothing is kept in a user-space buffer that a crash would lose. The sink never
// truncates what it did not create: only a file it was told is its own (create(),
// adopt_own()) is cut back by truncate(); on a stream truncate() fails with ESPIPE.
class FileSink final : public Sink {
 public:
  FileSink() = default;
  ~FileSink() override;
  FileSink(const FileSink&) = delete;
  FileSink& operator=(const FileSink&) = delete;
  FileSink(FileSink&& o) noexcept;
  FileSink& operator=(FileSink&& o) noexcept;

  // Creates `path`, which must not exist yet (O_EXCL). 0, or the errno of open(2).
  int create(const std::string& path);
  // Takes `fd`, a regular file the caller has just created (mkstemp(3)) and may cut back.
  void adopt_own(int fd);
  // Takes `fd`, written in place as a stream: a FIFO, a character device, standard output.
  void adopt_stream(int fd);
  int write(const std::uint8_t* data, std::size_t size) override;
  int truncate(std::uint64_t size) override;
  // fallocate(2) with FALLOC_FL_KEEP_SIZE: blocks past the end, the file's size unchanged.
  // On a file system without it and on a stream, 0 and no reservation (the ending may then
  // not fit).
  int reserve(std::uint64_t offset, std::uint64_t length) override;
  // fsync(2) (where the descriptor has it) then close(2); 0 or the errno.
  int close();
  bool is_open() const noexcept { return fd_ >= 0; }

 private:
  void take(int fd, bool own);
  int fd_ = -1;
  bool own_ = false;  // a regular file the sink created: truncate() and reserve() apply
  bool can_reserve_ = true;
};

}  // namespace pmu::mcap
