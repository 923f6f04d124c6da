#include "pmu/alarms/alarm_table.hpp"

#include "pmu/codec/messages.hpp"

namespace pmu::alarms {
namespace {

using namespace std::chrono_literals;

constexpr auto Pmu = DeviceKind::Pmu;
constexpr auto Battery = DeviceKind::Battery;
constexpr auto Mppt = DeviceKind::Mppt;
constexpr auto Bus = DeviceKind::Bus;
constexpr auto Any = DeviceKind::AnyDevice;
constexpr auto Warning = Severity::Warning;
constexpr auto Critical = Severity::Critical;
constexpr auto Flag = Condition::Flag;
constexpr auto Above = Condition::Above;
constexpr auto Below = Condition::Below;
constexpr auto Documented = Basis::Documented;
constexpr auto Chosen = Basis::Chosen;
constexpr std::uint8_t kVoltages = codec::group_bit::Voltages;
constexpr std::uint8_t kTemperatures = codec::group_bit::Temperatures;
constexpr std::uint8_t kStatus = codec::group_bit::Status;
constexpr std::uint8_t kNoPacket = 0;

// PMU: "v1.9" is millswood-250w-pmu-can-protocol-v1.9; battery and MPPT: the solar-boat
// CANopen document. Where neither gives a limit, the row is Chosen and its comment says why.
// Deadband and delays are there against chattering (ISA-18.2): a value that hovers at its
// limit, or a reading that blips once, raises nothing, and one that recovers briefly clears
// nothing.
constexpr std::array<AlarmSpec, kCodeCount> kTable{{
    // v1.9 5.5 table 6, flag register 0 bit 5; 5.14: in thermal shutdown all battery charging
    // ceases and the 28 VDC output takes the highest battery voltage. The PMU already applies
    // about 10 % hysteresis to T_U (5.14), so the flag is taken as it comes.
    {Code::ThermalShutdown, "thermal_shutdown", "thermal shutdown", Pmu, Critical, Flag, 0, "", 0, 0, 0ms, 0ms,
     Documented, kStatus},
    // v1.9 5.5 table 6, flag register 0 bit 6, from firmware 1.16 (6.8; before it the bit is
    // the start button, so only a Status whose interpretation says SoaShutdown feeds this).
    {Code::SoaShutdown, "soa_shutdown", "SOA shutdown", Pmu, Critical, Flag, 0, "", 0, 0, 0ms, 0ms, Documented,
     kStatus},
    // v1.9 5.5 table 6, flag register 0 bit 7. The aircraft still flies without its payload,
    // so a warning. The off-delay keeps a PMU that sheds and restores in turn to one alarm.
    {Code::PayloadShed, "payload_shed", "payload shed", Pmu, Warning, Flag, 0, "", 0, 0, 0ms, 5000ms, Documented,
     kStatus},
    // Battery voltages (v1.9 table 2: 0..25.0 V in 0.1 V steps). V_B may be set from 20.0 to
    // 25.2 V (5.10 table 11), and 25.2 V = 6 x 4.2 V: the PMU is built for a 6S Li-ion pack.
    // Absolute values for that pack, not a fraction of the stored V_B: V_B is the charging
    // voltage, which an operator may lower to spare the cells, while the voltage at which a
    // pack is empty stays where it is. Low 21.0 V = 3.5 V a cell, critical 19.8 V = 3.3 V a
    // cell, under load. On-delay 10 s as ArduPilot's BATT_LOW_TIMER: an engine start or a
    // servo load sags the voltage for less than that. Deadband 0.3 V = three steps of the
    // measurement. Another pack sets its own limits in the device's settings; a PMU with one
    // battery disables the other battery's rows there.
    {Code::BatteryALowVoltage, "battery_a_low_voltage", "battery A", Pmu, Warning, Below, 21.0, "V", 1, 0.3, 10000ms,
     10000ms, Chosen, kVoltages},
    {Code::BatteryACriticalVoltage, "battery_a_critical_voltage", "battery A", Pmu, Critical, Below, 19.8, "V", 1, 0.3,
     10000ms, 10000ms, Chosen, kVoltages},
    {Code::BatteryBLowVoltage, "battery_b_low_voltage", "battery B", Pmu, Warning, Below, 21.0, "V", 1, 0.3, 10000ms,
     10000ms, Chosen, kVoltages},
    {Code::BatteryBCriticalVoltage, "battery_b_critical_voltage", "battery B", Pmu, Critical, Below, 19.8, "V", 1, 0.3,
     10000ms, 10000ms, Chosen, kVoltages},
    // Temperatures (v1.9 table 5, 1 degC steps). The document gives the ranges, no ratings.
    // Deadbands are 10 % of the limit, the hysteresis the PMU itself applies to T_U (5.14).
    // Temperatures move slowly: a single reading over the limit is noise, so 5 s on and 10 s
    // off. Internal: the PMU's own limit is T_U, stored per unit with no documented default,
    // and thermal_shutdown reports it; this warns before it, 15 degC under the 85 degC
    // industrial rating of electronics, as the sensor sits inside the case. A unit whose T_U
    // is lower sets this limit a few degrees under its T_U.
    {Code::InternalOverTemperature, "internal_over_temperature", "PMU internal", Pmu, Warning, Above, 70, "degC", 0, 7,
     5000ms, 10000ms, Chosen, kTemperatures},
    // The starter module (table 5: -49..127 degC) heats while cranking: 85 degC, the top of
    // the industrial range (-40..85 degC) such modules are rated for.
    {Code::StarterOverTemperature, "starter_over_temperature", "starter", Pmu, Warning, Above, 85, "degC", 0, 8.5,
     5000ms, 10000ms, Chosen, kTemperatures},
    // The generator is a BLDC motor (table 5); 100 degC stays under the 120 degC at which
    // common (H grade) NdFeB magnets start to lose strength for good.
    {Code::GeneratorOverTemperature, "generator_over_temperature", "generator", Pmu, Warning, Above, 100, "degC", 0, 10,
     5000ms, 10000ms, Chosen, kTemperatures},
    // Li-ion cells are commonly rated for discharge up to 60 degC; past it they age fast and
    // come nearer to thermal runaway, hence critical.
    {Code::BatteryAOverTemperature, "battery_a_over_temperature", "battery A", Pmu, Critical, Above, 60, "degC", 0, 6,
     5000ms, 10000ms, Chosen, kTemperatures},
    {Code::BatteryBOverTemperature, "battery_b_over_temperature", "battery B", Pmu, Critical, Above, 60, "degC", 0, 6,
     5000ms, 10000ms, Chosen, kTemperatures},
    // The PMU reports no such fault: the PMU's session raises the flag while generation is
    // enabled (table 6, flag register 0 bit 4) and the engine is at its running speed (the
    // unit's engine.running_rpm) but the generator voltage (table 2) is below V_B, so it
    // cannot charge. 10 s on as for the battery voltages: while the engine comes up to speed
    // the voltage lags.
    {Code::GeneratorNotProducing, "generator_not_producing", "generator not producing", Pmu, Warning, Flag, 0, "", 0, 0,
     10000ms, 5000ms, Chosen, kVoltages | kStatus},
    // The PMU's session raises the flag when the generator speed (table 6) falls below the
    // unit's engine.running_rpm, having been at it, with no engine stop command (0x25) sent.
    // 1 s on: two or more status packets at the service's
    // usual 0.5 s, so one bad reading is not a stopped engine. Critical: the aircraft is on
    // battery alone.
    {Code::UncommandedEngineStop, "uncommanded_engine_stop", "engine stopped uncommanded", Pmu, Critical, Flag, 0, "",
     0, 0, 1000ms, 0ms, Chosen, kStatus},
    // State of charge (0x302 0x2005 0x05, 1 %/LSB). PX4's BAT_LOW_THR (15 %) and BAT_CRIT_THR
    // (7 %); its BAT_EMERGEN_THR (5 %) is an action, not an alarm, so it has no row. Deadband
    // 2 % so a reading that flips by one step does not clear it; 10 s as ArduPilot's timer.
    {Code::BmsLowSoc, "bms_low_soc", "SOC", Battery, Warning, Below, 15, "%", 0, 2, 10000ms, 10000ms, Chosen,
     kNoPacket},
    {Code::BmsCriticalSoc, "bms_critical_soc", "SOC", Battery, Critical, Below, 7, "%", 0, 2, 10000ms, 10000ms, Chosen,
     kNoPacket},
    // Lowest cell voltage (0x402 0x2005 0x0D, 1 mV/LSB): 3.30 V, the per-cell level of
    // battery_*_critical_voltage; one weak cell gets there before the pack does.
    {Code::CellLow, "cell_low", "cell", Battery, Warning, Below, 3.30, "V", 2, 0.05, 10000ms, 10000ms, Chosen,
     kNoPacket},
    // Highest minus lowest cell voltage (0x402 0x0C - 0x0D). 0.10 V: well past what a
    // balancing BMS leaves. Imbalance builds over many cycles, while a load step spreads the
    // cells for a moment, so 30 s each way.
    {Code::CellImbalance, "cell_imbalance", "cell spread", Battery, Warning, Above, 0.10, "V", 2, 0.02, 30000ms,
     30000ms, Chosen, kNoPacket},
    // Highest cell temperature (0x402 0x2005 0x09, 1 degC/LSB); 60 degC as for the PMU's
    // battery sensors above.
    {Code::BmsOverTemperature, "bms_over_temperature", "cells", Battery, Critical, Above, 60, "degC", 0, 6, 5000ms,
     10000ms, Chosen, kNoPacket},
    // The document names "MPPT State" (uint8) and "Safety Enabled" (bool) without their
    // values, so nothing says which is a fault, and the MPPT's session feeds nothing here
    // until a document does. 5 s each way so a state passed through on a change of light
    // raises nothing. A warning: the battery still carries the load.
    {Code::MpptFault, "mppt_fault", "MPPT fault", Mppt, Warning, Flag, 0, "", 0, 0, 5000ms, 5000ms, Chosen, kNoPacket},
    // The service's health (STALE / OFFLINE from frame age, docs/interface.md) already waits
    // its configured number of periods, so no delays here.
    {Code::DeviceStale, "device_stale", "device stale", Any, Warning, Flag, 0, "", 0, 0, 0ms, 0ms, Chosen, kNoPacket},
    {Code::DeviceOffline, "device_offline", "device offline", Any, Critical, Flag, 0, "", 0, 0, 0ms, 0ms, Chosen,
     kNoPacket},
    // The bus's state from the CAN controller (error counters over 127: error passive; over
    // 255: bus off). The counters fall by one a good frame, so a bus near 127 flips; 5 s off.
    {Code::BusErrorPassive, "bus_error_passive", "bus error passive", Bus, Warning, Flag, 0, "", 0, 0, 0ms, 5000ms,
     Chosen, kNoPacket},
    {Code::BusOff, "bus_off", "bus off", Bus, Critical, Flag, 0, "", 0, 0, 0ms, 0ms, Chosen, kNoPacket},
}};

// Rows are looked up by their code's number.
constexpr bool rows_in_code_order() {
  for (std::size_t i = 0; i < kTable.size(); ++i)
    if (static_cast<std::size_t>(kTable[i].code) != i) return false;
  return true;
}
static_assert(rows_in_code_order(), "kTable's rows must be in the order of enum Code");
static_assert(static_cast<std::size_t>(Code::BusOff) + 1 == kCodeCount, "kCodeCount must count enum Code");

}  // namespace

const std::array<AlarmSpec, kCodeCount>& alarm_table() noexcept { return kTable; }

const AlarmSpec& spec_of(Code c) noexcept { return kTable[static_cast<std::size_t>(c)]; }

std::string_view to_string(Code c) noexcept { return spec_of(c).name; }

std::optional<Code> code_named(std::string_view name) noexcept {
  for (const auto& row : kTable)
    if (row.name == name) return row.code;
  return std::nullopt;
}

std::string_view to_string(DeviceKind k) noexcept {
  switch (k) {
    case DeviceKind::Pmu: return "pmu";
    case DeviceKind::Battery: return "battery";
    case DeviceKind::Mppt: return "mppt";
    case DeviceKind::Bus: return "bus";
    case DeviceKind::AnyDevice: return "any device";
  }
  return "?";
}

std::string_view to_string(Severity s) noexcept {
  switch (s) {
    case Severity::Warning: return "warning";
    case Severity::Critical: return "critical";
  }
  return "?";
}

bool applies_to(const AlarmSpec& spec, DeviceKind kind) noexcept {
  if (spec.device == kind) return true;
  return spec.device == DeviceKind::AnyDevice && kind != DeviceKind::Bus && kind != DeviceKind::AnyDevice;
}

}  // namespace pmu::alarms
