#include "pmu/session/canopen_state.hpp"

namespace pmu::service {
namespace {

template <std::size_t N>
std::optional<std::size_t> slot_in(const CanOpenValue (&table)[N], std::string_view name) noexcept {
  for (std::size_t i = 0; i < N; ++i)
    if (table[i].name == name) return i;
  return std::nullopt;
}

template <std::size_t N, std::size_t M>
bool store(const CanOpenValue (&table)[N], CanOpenValues<M>& state, const codec::canopen::Field& f) noexcept {
  const auto slot = slot_in(table, f.name);
  if (!slot) return false;
  state.values[*slot] = f.value * table[*slot].scale;
  return true;
}

}  // namespace

std::optional<std::size_t> battery_slot(std::string_view name) noexcept { return slot_in(kBatteryValues, name); }
std::optional<std::size_t> mppt_slot(std::string_view name) noexcept { return slot_in(kMpptValues, name); }

Applied apply(const codec::canopen::CanOpenMessage& m, BatteryState& battery, BatteryCellsState& cells) noexcept {
  Applied a;
  if (m.source != codec::canopen::Source::Battery) return a;
  // 0x482 gives ("cell", n) then ("cell_voltage", V): one cell per frame.
  if (m.field_count == 2 && m.fields[0].name == "cell" && m.fields[1].name == "cell_voltage") {
    const auto cell = static_cast<std::size_t>(m.fields[0].value);
    if (cell < kMaxCells) {
      cells.volts[cell] = m.fields[1].value;
      a.cells = true;
    }
    return a;
  }
  for (std::uint8_t i = 0; i < m.field_count && i < m.fields.size(); ++i)
    a.battery |= store(kBatteryValues, battery, m.fields[i]);
  return a;
}

Applied apply(const codec::canopen::CanOpenMessage& m, MpptState& mppt) noexcept {
  Applied a;
  if (m.source != codec::canopen::Source::Mppt) return a;
  for (std::uint8_t i = 0; i < m.field_count && i < m.fields.size(); ++i)
    a.mppt |= store(kMpptValues, mppt, m.fields[i]);
  return a;
}

}  // namespace pmu::service
