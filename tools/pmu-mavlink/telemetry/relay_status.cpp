#include "telemetry/relay_status.hpp"

namespace pmu::mavlink_bridge {

namespace nm = pmu::mavlink;

PmuRelays pmu_relays(const PmuView& pmu) noexcept {
  PmuRelays r;
  // pmu/status carries the outputs' last read state; without ONLINE it may be old (H7).
  if (!pmu.online || !pmu.status) return r;
  const auto& s = *pmu.status;
  const bool by_instance[kRelaysPerPmu] = {s.avionics_servo_on(), s.payload_on(), s.charger_a_on(), s.charger_b_on(),
                                           s.generation_enabled()};
  for (unsigned i = 0; i < kRelaysPerPmu; ++i) {
    if (by_instance[i]) r.on = static_cast<std::uint16_t>(r.on | (1U << i));
  }
  r.present = (1U << kRelaysPerPmu) - 1U;
  return r;
}

nm::RelayStatus relay_status(const std::vector<std::pair<unsigned, const PmuView*>>& pmus, std::uint32_t time_boot_ms) {
  nm::RelayStatus m;
  m.time_boot_ms = time_boot_ms;
  for (const auto& [number, view] : pmus) {
    if (number >= kRelayStatusPmus || view == nullptr) continue;
    const PmuRelays r = pmu_relays(*view);
    const unsigned shift = kRelaysPerPmu * number;
    m.on = static_cast<std::uint16_t>(m.on | (r.on << shift));
    m.present = static_cast<std::uint16_t>(m.present | (r.present << shift));
  }
  return m;
}

}  // namespace pmu::mavlink_bridge
