#include "telemetry/battery_status.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace pmu::mavlink_bridge {
namespace battery_status_test {  // named: the unity build joins this file with others of its target
namespace {

namespace nm = pmu::mavlink;
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

PmuView full_pmu() {
  PmuView v;
  v.online = true;
  v.voltages.emplace();
  v.voltages->battery_a(24.1F);
  v.voltages->battery_b(23.5F);
  v.currents.emplace();
  v.currents->battery_a(-3.2F);  // discharging
  v.currents->battery_b(1.5F);   // charging
  v.temperatures.emplace();
  v.temperatures->battery_a(31.25F);
  v.temperatures->battery_b(kNaN);
  v.battery_energy.emplace();
  v.battery_energy->battery_a_mah(-420);
  v.battery_energy->battery_b_mah(150);
  v.energy.emplace();
  v.energy->battery_a().used_wh(10.0);
  v.energy->battery_a().endurance_s(1800.4F);
  v.energy->battery_b().used_wh(std::numeric_limits<double>::quiet_NaN());
  v.energy->battery_b().endurance_s(kNaN);
  return v;
}

TEST(PmuBatteryStatus, KnownValuesInMavlinkUnitsAndSign) {
  const auto m = pmu_battery_status(full_pmu(), BatteryInput::a, 10);
  EXPECT_EQ(m.id, 10);
  EXPECT_EQ(m.voltages[0], 24100);
  for (std::size_t i = 1; i < m.voltages.size(); ++i) EXPECT_EQ(m.voltages[i], UINT16_MAX) << "cell " << i;
  EXPECT_EQ(m.current_battery, 320) << "discharge is positive in MAVLink";
  EXPECT_EQ(m.temperature, 3125);
  EXPECT_EQ(m.current_consumed, 420);
  EXPECT_EQ(m.energy_consumed, 360);
  EXPECT_EQ(m.time_remaining, 1800);
  EXPECT_EQ(m.battery_remaining, -1) << "the PMU knows no state of charge";
  EXPECT_EQ(m.charge_state, nm::mav_battery_charge_state::kUndefined);
}

TEST(PmuBatteryStatus, ChargingInputAndItsUnknowns) {
  const auto m = pmu_battery_status(full_pmu(), BatteryInput::b, 11);
  EXPECT_EQ(m.id, 11);
  EXPECT_EQ(m.voltages[0], 23500);
  EXPECT_EQ(m.current_battery, -150);
  EXPECT_EQ(m.charge_state, nm::mav_battery_charge_state::kCharging);
  EXPECT_EQ(m.temperature, INT16_MAX) << "no sensor";
  EXPECT_EQ(m.current_consumed, 0) << "a net charge is nothing consumed";
  EXPECT_EQ(m.energy_consumed, -1);
  EXPECT_EQ(m.time_remaining, 0) << "0 is time_remaining's not provided";
}

// Every way the service says "not known" ends as the field's sentinel, never 0.
TEST(PmuBatteryStatus, EveryUnknownIsTheSentinel) {
  struct BatteryCase {
    const char* name;
    PmuView view;
  };
  PmuView nan_values = full_pmu();
  nan_values.voltages->battery_a(kNaN);
  nan_values.currents->battery_a(kNaN);
  nan_values.temperatures->battery_a(kNaN);
  nan_values.energy->battery_a().used_wh(std::numeric_limits<double>::quiet_NaN());
  nan_values.energy->battery_a().endurance_s(kNaN);
  nan_values.battery_energy.reset();
  PmuView stale = full_pmu();
  stale.online = false;
  PmuView nothing;
  nothing.online = true;
  const BatteryCase cases[] = {
      {"NaN in every sample", nan_values}, {"not ONLINE (H7)", stale}, {"no sample yet", nothing}};
  for (const auto& c : cases) {
    const auto m = pmu_battery_status(c.view, BatteryInput::a, 12);
    EXPECT_EQ(m.id, 12) << c.name;
    EXPECT_EQ(m.voltages[0], UINT16_MAX) << c.name;
    EXPECT_EQ(m.current_battery, -1) << c.name;
    EXPECT_EQ(m.temperature, INT16_MAX) << c.name;
    EXPECT_EQ(m.current_consumed, -1) << c.name;
    EXPECT_EQ(m.energy_consumed, -1) << c.name;
    EXPECT_EQ(m.battery_remaining, -1) << c.name;
    EXPECT_EQ(m.time_remaining, 0) << c.name;
    EXPECT_EQ(m.charge_state, nm::mav_battery_charge_state::kUndefined) << c.name;
  }
}

BmsView full_bms() {
  BmsView v;
  v.online = true;
  v.battery.emplace();
  v.battery->voltage(50.4F);
  v.battery->current(-12.0F);
  v.battery->cell_temperature_high(28.0F);
  v.battery->state_of_charge(76.6F);
  v.cells.emplace();
  for (unsigned char i = 1; i <= 12; ++i) {
    pmu::v5::BatteryCell c;
    c.cell(i);
    c.cell_voltage(i == 3 ? kNaN : 3.6F + 0.01F * i);
    v.cells->cells().push_back(c);
  }
  v.energy.emplace();
  v.energy->used_wh(100.0);
  v.energy->endurance_s(3600.0F);
  return v;
}

TEST(BmsBatteryStatus, CellsSocAndEnergy) {
  const auto m = bms_battery_status(full_bms(), 20);
  EXPECT_EQ(m.id, 20);
  EXPECT_EQ(m.voltages[0], 3610);
  EXPECT_EQ(m.voltages[2], UINT16_MAX) << "a cell not heard";
  EXPECT_EQ(m.voltages[9], 3700);
  EXPECT_EQ(m.voltages_ext[0], 3710);
  EXPECT_EQ(m.voltages_ext[1], 3720);
  EXPECT_EQ(m.voltages_ext[2], 0) << "cell 13 not heard: the ext field's not provided";
  EXPECT_EQ(m.current_battery, 1200);
  EXPECT_EQ(m.temperature, 2800);
  EXPECT_EQ(m.battery_remaining, 77);
  EXPECT_EQ(m.energy_consumed, 3600);
  EXPECT_EQ(m.time_remaining, 3600);
}

TEST(BmsBatteryStatus, PackVoltageInCellZeroWithoutCells) {
  BmsView v = full_bms();
  v.cells.reset();
  EXPECT_EQ(bms_battery_status(v, 20).voltages[0], 50400);
}

TEST(BmsBatteryStatus, EveryUnknownIsTheSentinel) {
  BmsView nan_values = full_bms();
  nan_values.cells.reset();
  nan_values.battery->voltage(kNaN);
  nan_values.battery->current(kNaN);
  nan_values.battery->cell_temperature_high(kNaN);
  nan_values.battery->state_of_charge(kNaN);
  nan_values.energy->used_wh(std::numeric_limits<double>::quiet_NaN());
  nan_values.energy->endurance_s(kNaN);
  BmsView stale = full_bms();
  stale.online = false;
  const std::pair<const char*, BmsView> cases[] = {{"NaN", nan_values}, {"not ONLINE (H7)", stale}};
  for (const auto& [name, view] : cases) {
    const auto m = bms_battery_status(view, 21);
    for (auto cell : m.voltages) EXPECT_EQ(cell, UINT16_MAX) << name;
    for (auto cell : m.voltages_ext) EXPECT_EQ(cell, 0) << name;
    EXPECT_EQ(m.current_battery, -1) << name;
    EXPECT_EQ(m.temperature, INT16_MAX) << name;
    EXPECT_EQ(m.battery_remaining, -1) << name;
    EXPECT_EQ(m.energy_consumed, -1) << name;
    EXPECT_EQ(m.time_remaining, 0) << name;
  }
}

}  // namespace
}  // namespace battery_status_test
}  // namespace pmu::mavlink_bridge
