#pragma once
// MAVLink 2 message signing (mavlink-devguide, guide/message_signing.md): a signed frame sets
// incompat flag 0x01 and carries link id, timestamp and the first 6 bytes of
// SHA-256(secret key + header + payload + CRC + link id + timestamp).
//
// One SigningLink per link (endpoint): the 32-byte key, the link id this side signs with,
// the link's timestamp, and the incoming streams' last timestamps. Time comes in as an
// argument (a signing timestamp: signing_timestamp() of the injected clock); nothing here
// reads a clock. Not thread-safe: the thread that parses and writes the link's frames calls it.
//
// Rules applied (the devguide's "Timestamp Handling" and "Accepting Signed Packets"):
// - each frame this side signs gets a timestamp at least 1 more than the previous one;
// - the link's timestamp is the larger of the clock and the newest correctly signed frame;
// - an incoming frame is refused when its signature does not match, when its timestamp is
//   not newer than the last one accepted for its (system id, component id, link id) stream
//   (a replay), or when it is more than one minute (6,000,000) behind the link's timestamp
//   (a new stream is accepted from any timestamp within that minute).
// Whether unsigned frames are accepted is the caller's rule (the devguide leaves it to the
// system); verify() reports them as Verdict::unsigned_frame and counts them.

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "pmu/mavlink/frame.hpp"

namespace pmu::mavlink {

using SecretKey = std::array<std::uint8_t, 32>;

// 2015-01-01T00:00:00Z as Unix time.
inline constexpr std::uint64_t kSigningEpochUnixSeconds = 1420070400;
// One minute in the timestamp's 10 us units.
inline constexpr std::uint64_t kSigningWindow = 6'000'000;
inline constexpr std::uint64_t kTimestampMask = (std::uint64_t{1} << 48) - 1;

// Unix time in microseconds as a signing timestamp (10 us units since 2015-01-01); 0 before
// that date.
constexpr std::uint64_t signing_timestamp(std::uint64_t unix_microseconds) noexcept {
  constexpr std::uint64_t epoch_us = kSigningEpochUnixSeconds * 1'000'000;
  return unix_microseconds < epoch_us ? 0 : ((unix_microseconds - epoch_us) / 10) & kTimestampMask;
}

// The 6-byte signature of a frame's bytes from the start marker to the end of the
// timestamp (header + payload + CRC + link id + timestamp).
std::array<std::uint8_t, 6> compute_signature(const SecretKey& key, const std::uint8_t* data,
                                              std::size_t size) noexcept;
// The same for a parsed frame (its bytes rebuilt from the header, the payload as on the wire,
// the CRC and the signature block); a zero signature for an unsigned frame.
std::array<std::uint8_t, 6> compute_signature(const SecretKey& key, const Frame& frame) noexcept;

enum class Verdict { accepted, unsigned_frame, bad_signature, replayed, stale, too_many_streams };

const char* to_string(Verdict verdict) noexcept;

struct SigningCounters {
  std::uint64_t signed_out = 0;
  std::uint64_t accepted = 0;
  std::uint64_t unsigned_frames = 0;
  std::uint64_t bad_signature = 0;
  std::uint64_t replayed = 0;
  std::uint64_t stale = 0;
  std::uint64_t too_many_streams = 0;
};

class SigningLink {
 public:
  // max_streams bounds the stream table: a frame of a new stream beyond it is refused
  // (too_many_streams), so a flood of forged system ids cannot grow memory.
  SigningLink(const SecretKey& key, std::uint8_t link_id, std::size_t max_streams = 64);

  std::uint8_t link_id() const noexcept { return link_id_; }
  const SecretKey& key() const noexcept { return key_; }
  // The link's timestamp: the newest of the clock, the frames signed and the frames accepted.
  std::uint64_t timestamp() const noexcept { return timestamp_; }

  // The timestamp for the next outgoing frame: max(now, the previous one + 1).
  std::uint64_t next_timestamp(std::uint64_t now) noexcept;
  void count_signed() noexcept { ++counters_.signed_out; }

  Verdict verify(const Frame& frame, std::uint64_t now);

  const SigningCounters& counters() const noexcept { return counters_; }

 private:
  struct Stream {
    std::uint8_t sysid;
    std::uint8_t compid;
    std::uint8_t link_id;
    std::uint64_t last;
  };

  SecretKey key_;
  std::uint8_t link_id_;
  std::size_t max_streams_;
  std::uint64_t timestamp_ = 0;
  std::vector<Stream> streams_;
  SigningCounters counters_;
};

}  // namespace pmu::mavlink
