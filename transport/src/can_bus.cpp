#include "pmu/transport/can_bus.hpp"

namespace pmu::transport {

std::string_view to_string(BusState state) noexcept {
  switch (state) {
    case BusState::Up: return "UP";
    case BusState::ErrorWarning: return "ERROR_WARNING";
    case BusState::ErrorPassive: return "ERROR_PASSIVE";
    case BusState::BusOff: return "BUS_OFF";
    case BusState::Down: return "DOWN";
  }
  return "UNKNOWN";
}

std::string_view to_string(SendStatus status) noexcept {
  switch (status) {
    case SendStatus::Sent: return "sent";
    case SendStatus::InvalidFrame: return "invalid frame";
    case SendStatus::Timeout: return "timeout";
    case SendStatus::Down: return "bus down";
    case SendStatus::BusOff: return "bus off";
    case SendStatus::NoDevice: return "no device";
    case SendStatus::Error: return "error";
    case SendStatus::Fenced: return "not the bus owner";
  }
  return "unknown";
}

bool is_sendable(const codec::CanFrame& frame) noexcept {
  const std::uint32_t max_id = frame.extended ? codec::kMaxExtendedId : codec::kMaxStandardId;
  return frame.id <= max_id && frame.length <= codec::kMaxDataLength;
}

}  // namespace pmu::transport
