#pragma once
// What the battery and MPPT tests over DDS share: a bus with a PMU, a battery and an MPPT,
// and frames built from spec/solar-boat-canopen-battery-mppt.txt's tables for a node that
// repeats them (BusThread, bus_thread.hpp).
#include <chrono>
#include <vector>

#include "support/canopen_frames.hpp"
#include "support/harness.hpp"
#include "bus_thread.hpp"

namespace pmu::service::test {

using namespace std::chrono_literals;

inline BusConfig bus_with_battery_and_mppt() {
  BusConfig b = sim_bus({device(1)});
  b.batteries.push_back(BatteryConfig{2, 1000ms, {}, {}});
  b.mppts.push_back(MpptConfig{4, 1000ms, {}});
  b.canopen_publish_period = 100ms;
  return b;
}

// From the document's tables: voltage 48.123 V (0x302 sub 0x01, 1 mV), BMS state (0x402
// sub 0x0E, uint32), the temperature collection (0x402 sub 0x0F), power level 77 % (0x202),
// cell 5 at 3.301 V (0x482); MPPT 4 (0x4E6 + 32 = 0x506): output voltage -100 counts, safety
// enabled, duty cycle of panel 2 = 45 % (0x507 sub 0x02).
inline std::vector<codec::CanFrame> document_frames() {
  return {
      canopen_frame(0x302, 0x2005, 0x01, {0xFB, 0xBB}),
      canopen_frame(0x402, 0x2005, 0x0E, {0x78, 0x56, 0x34, 0x12}),
      canopen_frame(0x402, 0x2005, 0x0F, {20, 21, 22, 23}),
      canopen_frame(0x202, 0, 0, {77}),
      canopen_frame(0x482, 0x2000, 5, {0xE5, 0x0C}),
      canopen_frame(mppt_id(4), 0, 0x00, {0x9C, 0xFF}),
      canopen_frame(mppt_id(4), 0, 0x04, {0x01}),
      canopen_frame(mppt_id(4, 1), 0, 0x02, {45}),
  };
}

}  // namespace pmu::service::test
