#pragma once
// Where a recording's bytes go, given the path an operator typed, chosen so that nothing the
// program did not create is removed, renamed over or truncated (docs/interface.md section 9.1):
//
//   path                      written to                          commit()        discard()
//   missing, regular file     NAME.partial-XXXXXX beside it       renamed to NAME removes it
//   symlink (chain)           as the path the chain ends at; the link itself stays a link
//   FIFO with a reader,       the node, in place, as a stream:    nothing         nothing
//     character device        never truncated, never renamed
//   "-"                       standard output, as a stream        nothing         nothing
//   directory, block device,  refused by open()
//     socket, FIFO without a reader, terminal, unwritable file, missing or unwritable folder
//
// A regular file is replaced only by a complete one (rename(2) in its folder), with the old
// file's permission bits (and owner, for root); a file that cannot be written (access(2)) is
// refused rather than replaced. A block device is refused because writing it in place would overwrite the file
// system it holds; a socket cannot be opened; a terminal would show binary.
//
// Nothing throws; every failure is a sentence naming the path. The destructor closes the
// file and removes a temporary file that was not committed (an exception while starting up
// leaves nothing behind), except after a failed commit(); a process killed outright leaves
// it, with the complete chunks written so far. Not thread-safe; open() reads the umask
// (umask(2) sets it too), so call it before other threads create files.

#include <sys/stat.h>

#include <cstdint>
#include <string>

#include "pmu/mcap/sink.hpp"

namespace pmu::mcap {

class OutputFile {
 public:
  OutputFile() = default;
  ~OutputFile();
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;
  OutputFile(OutputFile&& o) noexcept;
  OutputFile& operator=(OutputFile&& o) noexcept;

  // "" when the sink is ready, else why not ("cannot create rec.mcap: No such file or
  // directory", "out is a directory", ...); then nothing was created.
  std::string open(const std::string& path);
  // Lives as long as the OutputFile: a Writer given it must go first.
  Sink& sink() noexcept { return sink_; }

  // fsync(2) and close(2). 0 or the errno.
  int close();
  // After close(): the temporary file renamed over the target. "" or what failed; the bytes
  // then stay in the temporary file (the message names it), which only discard() removes.
  std::string commit();
  // Closes, and removes the temporary file if there is one. A stream keeps what it got.
  void discard();

  bool streaming() const noexcept { return kind_ == Kind::Stream; }
  // What the operator named: the path, or "standard output" for "-".
  const std::string& name() const noexcept { return name_; }
  // Where the bytes are until commit(): the temporary file, or the stream's path.
  const std::string& writing() const noexcept { return writing_; }

 private:
  enum class Kind { None, Replace, Stream };
  std::string open_stream(bool fifo);
  std::string open_replacement(const struct stat* replaced);  // nullptr: a new file
  std::string shown() const;                                  // "NAME", or "NAME (-> TARGET)" for a symlink

  FileSink sink_;
  Kind kind_ = Kind::None;
  std::string name_;
  std::string target_;  // the file commit() renames onto (symlinks followed)
  std::string writing_;
  bool temporary_ = false;  // writing_ is our temporary file, not yet renamed or removed
  bool keep_ = false;       // a commit() failed: the destructor leaves the temporary file
};

}  // namespace pmu::mcap
