#pragma once
// The latency from a CAN frame to its MAVLink message, beside the same frame's DDS sample.
// pmu-service reads the fake PMU's socketpair (service_run.hpp); two pmu-mavlink processes
// read the service, one sending BATTERY_STATUS at its highest rate (50 Hz, every pass of its
// 20 ms loop), one at its default (0.5 Hz); each sends to its own UDP socket in this process.
// Numbered voltages frames (fake_pmu.hpp) are written at 10 frames/s, the rate of one PMU
// streaming every 0.1 s; the number travels in the battery voltages, so BATTERY_STATUS ids
// 10 and 11 (battery A and B of PMU 1) carry it as their voltages[0]. Each frame is timed
// from its write to the first pmu/voltages sample at a reader in this process, and to the
// first BATTERY_STATUS pair carrying its number at each UDP socket: one run, the same frames.

#include "benchmarks.hpp"

namespace pmu::bench {

struct MavlinkLatencyOptions {
  std::string bridge_exe;  // pmu-mavlink
  double seconds = 60;     // how long frames are injected
  double frame_rate = 10;  // numbered frames per second
};

// Result rows (bench/report.py's format). Throws std::runtime_error when it cannot run:
// the service or a bridge does not start, or no BATTERY_STATUS carries a number.
Rows mavlink_latency_rows(const Settings& s, const MavlinkLatencyOptions& o, int domain);

}  // namespace pmu::bench
