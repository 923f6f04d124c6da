#include "pmu/transport/linux_frame.hpp"

#include <algorithm>

namespace pmu::transport {

struct can_frame to_linux(const codec::CanFrame& frame) noexcept {
  struct can_frame raw {};
  raw.can_id = frame.extended ? ((frame.id & CAN_EFF_MASK) | CAN_EFF_FLAG) : (frame.id & CAN_SFF_MASK);
  if (frame.remote) raw.can_id |= CAN_RTR_FLAG;
  raw.len = std::min(frame.length, codec::kMaxDataLength);
  std::copy_n(frame.data.begin(), raw.len, raw.data);
  return raw;
}

std::optional<codec::CanFrame> from_linux(const struct can_frame& raw) noexcept {
  if ((raw.can_id & CAN_ERR_FLAG) != 0 || raw.len > codec::kMaxDataLength) return std::nullopt;
  codec::CanFrame frame;
  frame.extended = (raw.can_id & CAN_EFF_FLAG) != 0;
  frame.remote = (raw.can_id & CAN_RTR_FLAG) != 0;
  frame.id = raw.can_id & (frame.extended ? CAN_EFF_MASK : CAN_SFF_MASK);
  frame.length = raw.len;
  std::copy_n(raw.data, raw.len, frame.data.begin());
  return frame;
}

}  // namespace pmu::transport
