#pragma once
// Messages to MAVLink 2 frames: trailing zero bytes of the payload truncated (the first byte
// always kept), the sequence number counted per writer, CRC with the message's CRC_EXTRA,
// and the signature block when a SigningLink is given.
// One writer per (system id, component id) and link, since the sequence number counts the
// frames one sender puts on one link. Not thread-safe.

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "pmu/mavlink/frame.hpp"
#include "pmu/mavlink/message_table.hpp"
#include "pmu/mavlink/signing.hpp"

namespace pmu::mavlink {

class FrameWriter {
 public:
  FrameWriter(std::uint8_t sysid, std::uint8_t compid) : sysid_(sysid), compid_(compid) {}

  template <class Message>
  std::vector<std::uint8_t> write(const Message& message) {
    Payload payload{};
    message.pack(payload);
    return encode(Message::kId, payload, nullptr, 0);
  }

  // Signed with the link's key and link id; `now` is the clock as a signing timestamp.
  template <class Message>
  std::vector<std::uint8_t> write_signed(const Message& message, SigningLink& signing, std::uint64_t now) {
    Payload payload{};
    message.pack(payload);
    return encode(Message::kId, payload, &signing, now);
  }

  // A payload of a message in the table (its max_length bytes are sent, less the truncated
  // zeros); an empty result for an id not in the table, whose CRC_EXTRA is unknown.
  std::vector<std::uint8_t> encode(std::uint32_t msgid, const Payload& payload, SigningLink* signing,
                                   std::uint64_t now);

  std::uint8_t next_sequence() const noexcept { return sequence_; }

 private:
  std::uint8_t sysid_;
  std::uint8_t compid_;
  std::uint8_t sequence_ = 0;
};

// The payload length after MAVLink 2's truncation of trailing zeros (never below 1).
std::size_t truncated_length(const Payload& payload, std::size_t full_length) noexcept;

}  // namespace pmu::mavlink
