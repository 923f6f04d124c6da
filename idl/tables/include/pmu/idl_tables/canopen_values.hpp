#pragma once
// The values of a battery (MG BMS) and an MPPT as the contract carries them (idl/canopen.idl,
// interface.md section 1.4): each field's name, the scale from the codec's value to the
// contract's unit, and the unit, in the order of the IDL fields, which is the order of the
// `received` bits. The service's CANopen sessions fill their slots in this order, the DDS core
// converts by it, and pmuctl labels what it shows with it. Pure data; any thread.

#include <cstddef>
#include <iterator>
#include <string_view>

namespace pmu::service {

struct CanOpenValue {
  std::string_view name;  // the contract's field name = the codec's value name
  double scale;           // codec value x scale = contract value
  std::string_view unit;  // the contract's unit ("" for raw counts, states and flags)
};

// pmu::v5::Battery's values, in IDL order.
inline constexpr CanOpenValue kBatteryValues[] = {
    {"voltage", 1, "V"},
    {"current", 1, "A"},
    {"current_discharge", 1, "A"},
    {"current_charge", 1, "A"},
    {"state_of_charge", 1, "%"},
    {"time_to_go", 60, "s"},  // the document's minutes, in the contract's seconds
    {"cell_temperature_high", 1, "degC"},
    {"cell_temperature_low", 1, "degC"},
    {"cell_voltage_high", 1, "V"},
    {"cell_voltage_low", 1, "V"},
    {"bms_state", 1, ""},
    {"temperature_1", 1, "degC"},
    {"temperature_2", 1, "degC"},
    {"temperature_3", 1, "degC"},
    {"temperature_4", 1, "degC"},
    {"power_level", 1, "%"},
};
inline constexpr std::size_t kBatteryValueCount = std::size(kBatteryValues);

// pmu::v5::Mppt's values, in IDL order. Voltages and currents are raw counts: the document gives
// them no resolution.
inline constexpr CanOpenValue kMpptValues[] = {
    {"voltage_output_raw", 1, ""},  {"current_output_raw", 1, ""},  {"voltage_out_sw_raw", 1, ""},
    {"mppt_state", 1, ""},          {"safety_enabled", 1, ""},      {"pwm_enabled", 1, ""},
    {"temperature", 1, "degC"},     {"voltage_panel_1_raw", 1, ""}, {"current_panel_1_raw", 1, ""},
    {"duty_cycle_panel_1", 1, "%"}, {"channel_1_active", 1, ""},    {"voltage_panel_2_raw", 1, ""},
    {"current_panel_2_raw", 1, ""}, {"duty_cycle_panel_2", 1, "%"}, {"channel_2_active", 1, ""},
    {"voltage_panel_3_raw", 1, ""}, {"current_panel_3_raw", 1, ""}, {"duty_cycle_panel_3", 1, "%"},
    {"channel_3_active", 1, ""},    {"voltage_panel_4_raw", 1, ""}, {"current_panel_4_raw", 1, ""},
    {"duty_cycle_panel_4", 1, "%"}, {"channel_4_active", 1, ""},
};
inline constexpr std::size_t kMpptValueCount = std::size(kMpptValues);

}  // namespace pmu::service
