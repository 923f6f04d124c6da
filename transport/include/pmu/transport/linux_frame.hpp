#pragma once
// codec::CanFrame <-> Linux `struct can_frame`. The only place the flag bits of can_id
// (CAN_EFF_FLAG, CAN_RTR_FLAG, CAN_ERR_FLAG) are packed and unpacked.
//
// Worked examples (also in tests/transport/linux_frame_test.cpp):
//   {id 0x1E000001, extended, len 2, FA 0A} <-> can_id 0x9E000001, len 2, data FA 0A
//   {id 0x202, standard, len 0}             <-> can_id 0x202, len 0

#include <linux/can.h>

#include <optional>

#include "pmu/codec/can_frame.hpp"

namespace pmu::transport {

// The caller checks is_sendable() first; bits beyond the id's kind are masked off here.
struct can_frame to_linux(const codec::CanFrame& frame) noexcept;

// A data or remote frame. nullopt for an error frame (CAN_ERR_FLAG) or a length above 8,
// which a classic CAN_RAW socket never delivers but another fd might.
std::optional<codec::CanFrame> from_linux(const struct can_frame& frame) noexcept;

}  // namespace pmu::transport
