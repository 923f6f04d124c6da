#include "pmu/config/low_rate.hpp"

namespace pmu::service {

bool LowRateGate::due(const std::string& bus, std::uint16_t address, std::size_t packet, TimePoint received) {
  if (!enabled() || packet >= kPackets) return false;
  auto& next = next_[{bus, address}][packet];
  if (next != TimePoint{} && received < next) return false;
  // On schedule: the next one is a period after this one was due. After a gap longer than a
  // period (a silent PMU, a late frame) the schedule restarts from this sample.
  const auto period = std::chrono::duration_cast<TimePoint::duration>(period_);
  next = (next == TimePoint{} || received - next >= period) ? received + period : next + period;
  return true;
}

}  // namespace pmu::service
