#pragma once
// The one way a program of pmu-dds reads a whole file it is given (the service config, a
// PMU's configuration file, the QoS file, the DDS-Security files, the moved-addresses state,
// pmuctl's config files): only a regular file, and only up to a stated size. A device
// (/dev/zero never ends), a FIFO (its open blocks until a writer comes) or a directory named
// where a file belongs would otherwise stop the start for ever or exhaust memory
// (docs/safety.md H12); each is refused with a reason instead.
//
// Total: every path gives the text or a reason, nothing throws but std::bad_alloc for a
// bound the machine cannot hold. Any thread may call it.

#include <cstddef>
#include <string>

namespace pmu::files {

struct FileText {
  std::string text;  // the whole file when error is empty
  // Why not, to follow "FILE cannot be read: ": the system's reason ("No such file or
  // directory"), "it is a FIFO, not a regular file", "it is 2 MiB, larger than the 1 MiB bound".
  std::string error;
  int system_error = 0;  // errno when the system refused (ENOENT: no such file); 0 otherwise

  bool ok() const noexcept { return error.empty(); }
};

// The whole of `path`, if it is a regular file of at most `max_bytes`. The file's type is
// taken before it is opened (a device is never opened) and again on the open descriptor,
// which is opened without blocking; a file that grows past the bound while read is refused.
FileText read_bounded_file(const std::string& path, std::size_t max_bytes);

// "1 MiB", "64 KiB", "100 bytes": a bound as an error message says it.
std::string size_text(std::size_t bytes);

}  // namespace pmu::files
