#include "pmu/mavlink/signing.hpp"

#include <openssl/sha.h>

#include <algorithm>
#include <tuple>

namespace pmu::mavlink {
namespace {

// A frame's bytes from the start marker to the end of the timestamp, rebuilt from its fields
// (the parser keeps the payload as it came: payload_length bytes).
std::size_t rebuild(const Frame& frame, std::array<std::uint8_t, kMaxFrameLength>& out) {
  std::size_t n = 0;
  out[n++] = kStartV2;
  out[n++] = frame.payload_length;
  out[n++] = frame.incompat_flags;
  out[n++] = frame.compat_flags;
  out[n++] = frame.sequence;
  out[n++] = frame.sysid;
  out[n++] = frame.compid;
  out[n++] = static_cast<std::uint8_t>(frame.msgid & 0xFFU);
  out[n++] = static_cast<std::uint8_t>((frame.msgid >> 8) & 0xFFU);
  out[n++] = static_cast<std::uint8_t>((frame.msgid >> 16) & 0xFFU);
  for (std::size_t i = 0; i < frame.payload_length; ++i) out[n++] = frame.payload[i];
  out[n++] = static_cast<std::uint8_t>(frame.checksum & 0xFFU);
  out[n++] = static_cast<std::uint8_t>(frame.checksum >> 8);
  const Signature& sig = *frame.signature;
  out[n++] = sig.link_id;
  for (int i = 0; i < 6; ++i) out[n++] = static_cast<std::uint8_t>((sig.timestamp >> (8 * i)) & 0xFFU);
  return n;
}

}  // namespace

std::array<std::uint8_t, 6> compute_signature(const SecretKey& key, const std::uint8_t* data,
                                              std::size_t size) noexcept {
  // The key and the frame in one buffer, hashed with the one-shot SHA256() (OpenSSL 3
  // deprecates the SHA256_Init/Update/Final steps).
  std::array<std::uint8_t, std::tuple_size<SecretKey>::value + kMaxFrameLength> input{};
  size = std::min(size, kMaxFrameLength);
  std::copy(key.begin(), key.end(), input.begin());
  std::copy(data, data + size, input.begin() + static_cast<std::ptrdiff_t>(key.size()));
  std::array<std::uint8_t, SHA256_DIGEST_LENGTH> digest{};
  SHA256(input.data(), key.size() + size, digest.data());
  std::array<std::uint8_t, 6> out{};
  std::copy(digest.begin(), digest.begin() + 6, out.begin());
  return out;
}

std::array<std::uint8_t, 6> compute_signature(const SecretKey& key, const Frame& frame) noexcept {
  if (!frame.signature) return {};
  std::array<std::uint8_t, kMaxFrameLength> bytes{};
  const std::size_t n = rebuild(frame, bytes);
  return compute_signature(key, bytes.data(), n);
}

const char* to_string(Verdict verdict) noexcept {
  switch (verdict) {
    case Verdict::accepted: return "accepted";
    case Verdict::unsigned_frame: return "unsigned";
    case Verdict::bad_signature: return "bad signature";
    case Verdict::replayed: return "replayed (timestamp not newer than the stream's last)";
    case Verdict::stale: return "stale (more than a minute behind the link's timestamp)";
    case Verdict::too_many_streams: return "too many signing streams";
  }
  return "unknown";
}

SigningLink::SigningLink(const SecretKey& key, std::uint8_t link_id, std::size_t max_streams)
    : key_(key), link_id_(link_id), max_streams_(max_streams) {}

std::uint64_t SigningLink::next_timestamp(std::uint64_t now) noexcept {
  timestamp_ = std::max(now & kTimestampMask, timestamp_ + 1) & kTimestampMask;
  return timestamp_;
}

Verdict SigningLink::verify(const Frame& frame, std::uint64_t now) {
  if (!frame.signature) {
    ++counters_.unsigned_frames;
    return Verdict::unsigned_frame;
  }
  if (compute_signature(key_, frame) != frame.signature->value) {
    ++counters_.bad_signature;
    return Verdict::bad_signature;
  }
  const std::uint64_t stamp = frame.signature->timestamp;
  const std::uint64_t local = std::max(now & kTimestampMask, timestamp_);
  auto stream = std::find_if(streams_.begin(), streams_.end(), [&](const Stream& s) {
    return s.sysid == frame.sysid && s.compid == frame.compid && s.link_id == frame.signature->link_id;
  });
  if (stream != streams_.end() && stamp <= stream->last) {
    ++counters_.replayed;
    return Verdict::replayed;
  }
  if (stamp + kSigningWindow < local) {
    ++counters_.stale;
    return Verdict::stale;
  }
  if (stream == streams_.end()) {
    if (streams_.size() >= max_streams_) {
      ++counters_.too_many_streams;
      return Verdict::too_many_streams;
    }
    streams_.push_back({frame.sysid, frame.compid, frame.signature->link_id, stamp});
  } else {
    stream->last = stamp;
  }
  timestamp_ = std::max(local, stamp);
  ++counters_.accepted;
  return Verdict::accepted;
}

}  // namespace pmu::mavlink
