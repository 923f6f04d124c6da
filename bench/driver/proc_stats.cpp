#include "proc_stats.hpp"

#include <unistd.h>

#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

namespace pmu::bench {

ProcSample proc_sample(pid_t pid) {
  const std::string dir = "/proc/" + std::to_string(pid);
  ProcSample s;
  std::ifstream stat(dir + "/stat");
  std::string line;
  if (!std::getline(stat, line)) throw std::runtime_error("process " + std::to_string(pid) + " is gone");
  // Field 2 (comm) may hold spaces: count fields from the closing parenthesis.
  std::istringstream rest(line.substr(line.rfind(')') + 2));
  std::string field;
  unsigned long utime = 0, stime = 0;
  for (int i = 3; i <= 15 && rest >> field; ++i) {
    if (i == 14) utime = std::stoul(field);
    if (i == 15) stime = std::stoul(field);
  }
  s.cpu_seconds = static_cast<double>(utime + stime) / static_cast<double>(::sysconf(_SC_CLK_TCK));
  std::ifstream status(dir + "/status");
  while (std::getline(status, line)) {
    if (line.rfind("VmRSS:", 0) == 0) s.rss_mib = std::stod(line.substr(6)) / 1024.0;  // kB
    if (line.rfind("Threads:", 0) == 0) s.threads = std::stoi(line.substr(8));
  }
  return s;
}

double cpu_percent(const ProcSample& before, const ProcSample& after, double wall_seconds) noexcept {
  return wall_seconds > 0 ? 100.0 * (after.cpu_seconds - before.cpu_seconds) / wall_seconds : 0.0;
}

}  // namespace pmu::bench
