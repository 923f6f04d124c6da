#include "pmu/baseline/apply_plan.hpp"

#include <algorithm>
#include <array>

namespace pmu::baseline {

int apply_rank(Setting s) noexcept {
  // Indexed by Setting; the header says why this order.
  constexpr std::array<int, kSettingCount> kRank{
      7,   // avionics_voltage
      8,   // payload_voltage
      6,   // servo_voltage
      5,   // battery_voltage
      11,  // packet_period
      12,  // packets_streamed
      0,   // temperature_offset
      1,   // upper_temperature_limit
      3,   // power_up_state
      2,   // cranking_time
      13,  // can_address
      10,  // outputs
      9,   // generation_enabled
  };
  return kRank[static_cast<std::size_t>(s)];
}

service::CommandAction action_for(Setting setting, std::uint32_t raw) {
  if (setting == Setting::Outputs) return service::action::SetOutputs{static_cast<std::uint8_t>(raw)};
  if (setting == Setting::GenerationEnabled) return service::action::SetGeneration{raw != 0};
  return service::action::SetParameter{*parameter_of(setting), raw};
}

Undo undo_of(const Change& c, std::optional<std::uint32_t> device_now) noexcept {
  if (!device_now) return Undo::NotRead;
  return *device_now == c.to ? Undo::Restore : Undo::ChangedByAnother;
}

std::vector<Change> apply_plan(const std::vector<Difference>& diffs, const service::DeviceUse& device) {
  std::vector<Change> out;
  for (const auto& d : diffs) {
    service::CommandRequest r;
    r.action = action_for(d.setting, d.file);
    out.push_back({d.setting, d.device.value_or(0), d.file, d.line, service::confirm_rule_for(r, device)});
  }
  std::stable_sort(out.begin(), out.end(),
                   [](const Change& a, const Change& b) { return apply_rank(a.setting) < apply_rank(b.setting); });
  return out;
}

}  // namespace pmu::baseline
