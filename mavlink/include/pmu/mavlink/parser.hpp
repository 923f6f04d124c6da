#pragma once
// The streaming MAVLink 2 parser: bytes in, in any chunking; frames and counted rejections
// out. Nothing here throws or allocates per byte; errors are counters (ParserCounters) and
// rejection values, never exceptions.
//
// Use: push() what a read returned, then call next() until it returns nullopt (it needs more
// bytes). The parser buffers at most one pushed chunk plus an incomplete frame.
// One parser per byte stream; not thread-safe (one thread calls it).
//
// What it does with each start of a frame:
// - a MAVLink 2 frame of a known message (message_table.hpp) with a good CRC: a Frame;
// - known message, bad CRC: a Rejection (bad_crc), and the search for the next start marker
//   resumes at the byte after this one (resynchronisation: a start marker inside garbage or
//   a damaged frame costs no real frame behind it);
// - unknown message id: its CRC cannot be checked (no CRC_EXTRA), so it is not delivered: a
//   Rejection (unknown_message), and the frame is skipped whole, because on a link shared
//   with an autopilot most frames are messages this side does not know;
// - an incompat flag other than signing: a Rejection (unsupported_incompat_flags), resync;
// - a MAVLink 1 frame (0xFE) of a known message with a good CRC: a Rejection (mavlink1),
//   skipped whole; a 0xFE that is no such frame counts as garbage;
// - bytes before a start marker: garbage_bytes.
// Signatures are not checked here: signing.hpp's SigningLink::verify does that.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <variant>
#include <vector>

#include "pmu/mavlink/frame.hpp"

namespace pmu::mavlink {

struct ParserCounters {
  std::uint64_t frames = 0;
  std::uint64_t bad_crc = 0;
  std::uint64_t unknown_message = 0;
  std::uint64_t unsupported_incompat_flags = 0;
  std::uint64_t mavlink1_frames = 0;
  std::uint64_t garbage_bytes = 0;
};

enum class RejectReason { bad_crc, unknown_message, unsupported_incompat_flags, mavlink1 };

const char* to_string(RejectReason reason) noexcept;

struct Rejection {
  RejectReason reason = RejectReason::bad_crc;
  // From the rejected frame's header, as read (not trustworthy for bad_crc).
  std::uint32_t msgid = 0;
  std::uint8_t sysid = 0;
  std::uint8_t compid = 0;
};

using ParseResult = std::variant<Frame, Rejection>;

class Parser {
 public:
  void push(const std::uint8_t* data, std::size_t size);
  // The next frame or rejection the pushed bytes hold; nullopt when more bytes are needed.
  std::optional<ParseResult> next();

  const ParserCounters& counters() const noexcept { return counters_; }
  std::size_t buffered() const noexcept { return buffer_.size() - start_; }

 private:
  std::vector<std::uint8_t> buffer_;
  std::size_t start_ = 0;  // first byte not yet consumed
  ParserCounters counters_;
};

}  // namespace pmu::mavlink
