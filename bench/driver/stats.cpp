#include "stats.hpp"

#include <algorithm>
#include <cmath>

namespace pmu::bench {
namespace {

double at(const std::vector<std::int64_t>& sorted, double q) {
  const auto n = sorted.size();
  auto rank = static_cast<std::size_t>(std::ceil(q * static_cast<double>(n)));
  rank = std::clamp<std::size_t>(rank, 1, n);
  return static_cast<double>(sorted[rank - 1]) / 1000.0;
}

}  // namespace

Percentiles percentiles(std::vector<std::int64_t>& ns) {
  Percentiles p;
  p.count = ns.size();
  if (ns.empty()) return p;
  std::sort(ns.begin(), ns.end());
  p.p50_us = at(ns, 0.50);
  p.p99_us = at(ns, 0.99);
  p.p999_us = at(ns, 0.999);
  p.max_us = static_cast<double>(ns.back()) / 1000.0;
  return p;
}

}  // namespace pmu::bench
