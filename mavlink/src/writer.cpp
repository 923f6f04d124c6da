#include "pmu/mavlink/writer.hpp"

#include "pmu/mavlink/crc.hpp"

namespace pmu::mavlink {

std::size_t truncated_length(const Payload& payload, std::size_t full_length) noexcept {
  std::size_t length = full_length;
  while (length > 1 && payload[length - 1] == 0) --length;
  return length;
}

std::vector<std::uint8_t> FrameWriter::encode(std::uint32_t msgid, const Payload& payload, SigningLink* signing,
                                              std::uint64_t now) {
  const MessageInfo* info = find_message(msgid);
  if (info == nullptr) return {};
  const std::size_t length = truncated_length(payload, info->max_length);
  std::vector<std::uint8_t> out;
  out.reserve(kHeaderLength + length + kChecksumLength + (signing != nullptr ? kSignatureLength : 0));
  out.push_back(kStartV2);
  out.push_back(static_cast<std::uint8_t>(length));
  out.push_back(signing != nullptr ? kIncompatSigned : 0);
  out.push_back(0);  // compat flags
  out.push_back(sequence_++);
  out.push_back(sysid_);
  out.push_back(compid_);
  out.push_back(static_cast<std::uint8_t>(msgid & 0xFFU));
  out.push_back(static_cast<std::uint8_t>((msgid >> 8) & 0xFFU));
  out.push_back(static_cast<std::uint8_t>((msgid >> 16) & 0xFFU));
  out.insert(out.end(), payload.begin(), payload.begin() + static_cast<std::ptrdiff_t>(length));
  std::uint16_t crc = crc_accumulate(out.data() + 1, out.size() - 1, kCrcInit);
  crc = crc_accumulate(info->crc_extra, crc);
  out.push_back(static_cast<std::uint8_t>(crc & 0xFFU));
  out.push_back(static_cast<std::uint8_t>(crc >> 8));
  if (signing != nullptr) {
    const std::uint64_t stamp = signing->next_timestamp(now);
    out.push_back(signing->link_id());
    for (int i = 0; i < 6; ++i) out.push_back(static_cast<std::uint8_t>((stamp >> (8 * i)) & 0xFFU));
    const auto sig = compute_signature(signing->key(), out.data(), out.size());
    out.insert(out.end(), sig.begin(), sig.end());
    signing->count_signed();
  }
  return out;
}

}  // namespace pmu::mavlink
