#pragma once
// One MAVLink 2 frame as the parser delivers it: the header, the payload with the zeros the
// sender truncated restored, the checksum, and the signature block when the frame is signed.
//
// Wire layout (MAVLink 2): 0xFD, payload length, incompat flags, compat flags, sequence,
// system id, component id, message id (3 bytes, little-endian), payload, CRC (2 bytes,
// little-endian), and with incompat flag 0x01 the 13-byte signature block: link id,
// timestamp (6 bytes, little-endian, 10 us units since 2015-01-01), signature (6 bytes).

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>

namespace pmu::mavlink {

inline constexpr std::uint8_t kStartV2 = 0xFD;
inline constexpr std::uint8_t kStartV1 = 0xFE;
inline constexpr std::size_t kHeaderLength = 10;  // start marker to message id
inline constexpr std::size_t kChecksumLength = 2;
inline constexpr std::size_t kSignatureLength = 13;
inline constexpr std::size_t kMaxPayloadLength = 255;
inline constexpr std::size_t kMaxFrameLength = kHeaderLength + kMaxPayloadLength + kChecksumLength + kSignatureLength;
// The only incompat flag MAVLink 2 defines; a frame with any other incompat bit is refused
// (the spec: a library must drop a frame with an incompat flag it does not understand).
inline constexpr std::uint8_t kIncompatSigned = 0x01;

using Payload = std::array<std::uint8_t, kMaxPayloadLength>;

struct Signature {
  std::uint8_t link_id = 0;
  std::uint64_t timestamp = 0;  // 48 bits used
  std::array<std::uint8_t, 6> value{};
};

struct Frame {
  std::uint8_t sequence = 0;
  std::uint8_t sysid = 0;
  std::uint8_t compid = 0;
  std::uint32_t msgid = 0;
  std::uint8_t incompat_flags = 0;
  std::uint8_t compat_flags = 0;
  // As on the wire, after the sender's truncation of trailing zero bytes.
  std::uint8_t payload_length = 0;
  // Zero beyond payload_length, so a message reads its full length (truncated zeros and
  // extension fields an older sender does not know both read as 0).
  Payload payload{};
  std::uint16_t checksum = 0;
  std::optional<Signature> signature;
};

}  // namespace pmu::mavlink
