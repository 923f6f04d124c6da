#pragma once
// Which CAN identifiers a bus passes up. One table serves twice: SocketCanBus installs it as
// kernel filters (CAN_RAW_FILTER) and also checks it in userspace, because an adopted fd
// (a socketpair in tests) has no kernel filter, and the check costs nothing next to a syscall.
//
// Worked examples (also in tests/transport/filters_test.cpp):
//   extended 0x1E000001 (PMU voltages, address 1)   -> pmu_filter() accepts
//   extended 0x1F000001 (another group)             -> rejected
//   standard 0x202 (CANopen battery power level)    -> canopen_filters() accepts
//   standard 0x4E5 (just below the MPPT blocks)     -> rejected

#include <cstdint>
#include <vector>

#include "pmu/codec/can_frame.hpp"

namespace pmu::transport {

// Matches a frame when the frame's kind (11/29-bit) equals `extended` and
// (frame.id & mask) == (id & mask). The same semantics as a `struct can_filter` whose
// mask includes CAN_EFF_FLAG.
struct IdFilter {
  std::uint32_t id = 0;
  std::uint32_t mask = 0;
  bool extended = false;

  bool matches(const codec::CanFrame& frame) const noexcept {
    return frame.extended == extended && (frame.id & mask) == (id & mask);
  }
};

// The PMU's extended ids: group 0x1E in bits 28..24 (protocol v1.9 section 4).
IdFilter pmu_filter() noexcept;

// The solar-boat battery (0x202, 0x302, 0x402, 0x482) and MPPT (0x4E6..0x51F) 11-bit ids,
// the range split into aligned mask blocks.
std::vector<IdFilter> canopen_filters();

// What the service listens to: the PMU, plus the CANopen devices when asked for.
std::vector<IdFilter> default_filters(bool with_canopen);

// True when any filter matches; an empty list accepts every frame.
bool accepts(const std::vector<IdFilter>& filters, const codec::CanFrame& frame) noexcept;

}  // namespace pmu::transport
