#pragma once
// What /proc says about a process: CPU time (user+system), resident memory, threads.

#include <sys/types.h>

#include <cstdint>

namespace pmu::bench {

struct ProcSample {
  double cpu_seconds = 0;  // utime + stime, all threads (exited ones included)
  double rss_mib = 0;      // VmRSS
  int threads = 0;
};

// Throws std::runtime_error when the process is gone.
ProcSample proc_sample(pid_t pid);

// CPU use between two samples as a percentage of one core.
double cpu_percent(const ProcSample& before, const ProcSample& after, double wall_seconds) noexcept;

}  // namespace pmu::bench
