#pragma once
// The service benchmarks, each beside its bare-Fast-DDS reference from the same
// run. Each prints result rows (JSON lines, bench/report.py's format) on stdout and its
// progress on stderr.

#include <nlohmann/json.hpp>
#include <vector>

#include "service_run.hpp"

namespace pmu::bench {

using Rows = std::vector<nlohmann::json>;

// Start-up, idle CPU, memory, latency and CPU at a saturated bus, command round trip and
// the highest zero-loss rate, over Fast DDS's default transports (shared memory between
// processes on one host) and the latency again over UDP only; then how CPU and memory grow
// with PMUs and subscribers (scale_bench.hpp).
Rows run_all(const Settings& s);

}  // namespace pmu::bench
