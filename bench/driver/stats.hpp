#pragma once
// Percentiles of latency samples (nanoseconds), reported in microseconds.

#include <cstdint>
#include <vector>

namespace pmu::bench {

struct Percentiles {
  std::size_t count = 0;
  double p50_us = 0, p99_us = 0, p999_us = 0, max_us = 0;
};

// Nearest-rank percentiles; sorts `ns` in place.
Percentiles percentiles(std::vector<std::int64_t>& ns);

}  // namespace pmu::bench
