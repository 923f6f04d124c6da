#include "pmu/mavlink/parser.hpp"

#include <algorithm>

#include "pmu/mavlink/crc.hpp"
#include "pmu/mavlink/message_table.hpp"

namespace pmu::mavlink {
namespace {

// What one look at the bytes from a start marker gives.
enum class Step { need_more, not_a_frame, result };

struct Look {
  Step step = Step::need_more;
  std::size_t consumed = 0;  // for Step::result: the bytes the result covers
  std::optional<ParseResult> result;
};

Look reject(RejectReason reason, std::uint32_t msgid, std::uint8_t sysid, std::uint8_t compid, std::size_t consumed) {
  return {Step::result, consumed, ParseResult{Rejection{reason, msgid, sysid, compid}}};
}

// MAVLink 1: 0xFE, length, sequence, system, component, message id, payload, CRC. Only a
// frame that checks (known id, its v1 length, good CRC) is taken for one.
Look look_v1(const std::uint8_t* p, std::size_t available) {
  constexpr std::size_t kV1Overhead = 8;
  if (available < 2) return {};
  const std::size_t total = p[1] + kV1Overhead;
  if (available < total) return {};
  const MessageInfo* info = find_message(p[5]);
  if (info == nullptr || info->min_length != p[1]) return {Step::not_a_frame, 0, std::nullopt};
  std::uint16_t crc = crc_accumulate(p + 1, 5U + p[1], kCrcInit);
  crc = crc_accumulate(info->crc_extra, crc);
  const auto wire = static_cast<std::uint16_t>(p[6 + p[1]] | (p[7 + p[1]] << 8));
  if (crc != wire) return {Step::not_a_frame, 0, std::nullopt};
  return reject(RejectReason::mavlink1, p[5], p[3], p[4], total);
}

std::uint64_t read_le48(const std::uint8_t* p) {
  std::uint64_t v = 0;
  for (int i = 5; i >= 0; --i) v = (v << 8) | p[i];
  return v;
}

}  // namespace

const char* to_string(RejectReason reason) noexcept {
  switch (reason) {
    case RejectReason::bad_crc: return "bad CRC";
    case RejectReason::unknown_message: return "unknown message id";
    case RejectReason::unsupported_incompat_flags: return "unsupported incompat flags";
    case RejectReason::mavlink1: return "MAVLink 1 frame";
  }
  return "unknown";
}

void Parser::push(const std::uint8_t* data, std::size_t size) {
  if (start_ > 0 && start_ >= buffer_.size() / 2) {
    buffer_.erase(buffer_.begin(), buffer_.begin() + static_cast<std::ptrdiff_t>(start_));
    start_ = 0;
  }
  buffer_.insert(buffer_.end(), data, data + size);
}

std::optional<ParseResult> Parser::next() {
  while (true) {
    const auto begin = buffer_.begin() + static_cast<std::ptrdiff_t>(start_);
    const auto marker =
        std::find_if(begin, buffer_.end(), [](std::uint8_t b) { return b == kStartV2 || b == kStartV1; });
    counters_.garbage_bytes += static_cast<std::uint64_t>(marker - begin);
    start_ = static_cast<std::size_t>(marker - buffer_.begin());
    if (marker == buffer_.end()) {
      buffer_.clear();
      start_ = 0;
      return std::nullopt;
    }
    const std::uint8_t* p = buffer_.data() + start_;
    const std::size_t available = buffer_.size() - start_;

    Look look;
    if (*p == kStartV1) {
      look = look_v1(p, available);
      if (look.step == Step::result) ++counters_.mavlink1_frames;
    } else {
      if (available < kHeaderLength) return std::nullopt;
      const std::uint8_t length = p[1];
      const std::uint8_t incompat = p[2];
      const std::uint32_t id =
          p[7] | (static_cast<std::uint32_t>(p[8]) << 8) | (static_cast<std::uint32_t>(p[9]) << 16);
      if ((incompat & static_cast<std::uint8_t>(~kIncompatSigned)) != 0) {
        ++counters_.unsupported_incompat_flags;
        // The frame's length is unknown with a flag not understood: resynchronise.
        look = reject(RejectReason::unsupported_incompat_flags, id, p[5], p[6], 1);
      } else {
        const bool is_signed = (incompat & kIncompatSigned) != 0;
        const std::size_t total = kHeaderLength + length + kChecksumLength + (is_signed ? kSignatureLength : 0);
        if (available < total) return std::nullopt;
        const MessageInfo* info = find_message(id);
        if (info == nullptr) {
          ++counters_.unknown_message;
          look = reject(RejectReason::unknown_message, id, p[5], p[6], total);
        } else {
          std::uint16_t crc = crc_accumulate(p + 1, kHeaderLength - 1 + length, kCrcInit);
          crc = crc_accumulate(info->crc_extra, crc);
          const std::uint8_t* c = p + kHeaderLength + length;
          const auto wire = static_cast<std::uint16_t>(c[0] | (c[1] << 8));
          if (crc != wire) {
            ++counters_.bad_crc;
            look = reject(RejectReason::bad_crc, id, p[5], p[6], 1);
          } else {
            Frame frame;
            frame.incompat_flags = incompat;
            frame.compat_flags = p[3];
            frame.sequence = p[4];
            frame.sysid = p[5];
            frame.compid = p[6];
            frame.msgid = id;
            frame.payload_length = length;
            std::copy(p + kHeaderLength, p + kHeaderLength + length, frame.payload.begin());
            frame.checksum = wire;
            if (is_signed) {
              const std::uint8_t* s = c + kChecksumLength;
              Signature sig;
              sig.link_id = s[0];
              sig.timestamp = read_le48(s + 1);
              std::copy(s + 7, s + 13, sig.value.begin());
              frame.signature = sig;
            }
            ++counters_.frames;
            look = {Step::result, total, ParseResult{std::move(frame)}};
          }
        }
      }
    }

    switch (look.step) {
      case Step::need_more: return std::nullopt;
      case Step::not_a_frame:
        ++counters_.garbage_bytes;
        ++start_;
        continue;
      case Step::result: start_ += look.consumed; return std::move(look.result);
    }
  }
}

}  // namespace pmu::mavlink
