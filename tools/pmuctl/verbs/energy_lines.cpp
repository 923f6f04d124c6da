#include "pmuctl/verbs/energy_lines.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <string>

#include "pmu/dds/contract_names.hpp"
#include "pmuctl/view/sample_fields.hpp"

namespace pmu::tools {
// A namespace of its own: the unity builds put this file in one translation unit with the
// verbs, whose helpers have the same names.
namespace energy_lines {
namespace {

using Json = nlohmann::json;

// NaN (not known) is null in JSON. A float as the shortest decimal that is the same float32,
// as the other verbs print the contract's floats.
Json number_or_null(float v) {
  return std::isfinite(v) ? Json(std::strtod(shortest(v).c_str(), nullptr)) : Json(nullptr);
}
Json number_or_null(double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); }

void print_json(Json j) {
  j["contract"] = pmu::dds::contract_major();
  std::printf("%s\n", j.dump(-1, ' ', false, Json::error_handler_t::replace).c_str());
}

Json battery_json(const pmu::v5::EnergyBattery& b) {
  return {{"power", number_or_null(b.power())},
          {"used_wh", number_or_null(b.used_wh())},
          {"integrated_s", number_or_null(b.integrated_s())},
          {"endurance_s", number_or_null(b.endurance_s())},
          {"critical_voltage", number_or_null(b.critical_voltage())}};
}

// "12.3 W", or "-" when not known.
std::string watts(float w) {
  if (!std::isfinite(w)) return "-";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f W", static_cast<double>(w));
  return buf;
}

// "1 h 02 min", "14 min", "45 s"; "-" when not known.
std::string duration_text(float s) {
  if (!std::isfinite(s)) return "-";
  const long total = std::lround(static_cast<double>(s));
  char buf[32];
  if (total >= 3600)
    std::snprintf(buf, sizeof buf, "%ld h %02ld min", total / 3600, (total % 3600) / 60);
  else if (total >= 60)
    std::snprintf(buf, sizeof buf, "%ld min", total / 60);
  else
    std::snprintf(buf, sizeof buf, "%ld s", total);
  return buf;
}

// "20.0 Ah", or "-" when not configured.
std::string amp_hours(float ah) {
  if (!std::isfinite(ah)) return "-";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f Ah", static_cast<double>(ah));
  return buf;
}

void print_battery(const char* name, const pmu::v5::EnergyBattery& b) {
  std::printf("  %-10s %10s  used %8.3f Wh in %.0f s  endurance %s to %.1f V\n", name, watts(b.power()).c_str(),
              b.used_wh(), static_cast<double>(b.integrated_s()), duration_text(b.endurance_s()).c_str(),
              static_cast<double>(b.critical_voltage()));
}

void print_pmu(const GlobalOptions& o, const pmu::v5::Energy& e) {
  if (o.json) {
    Json values{{"avionics_power", number_or_null(e.avionics_power())},
                {"output_28v_power", number_or_null(e.output_28v_power())},
                {"payload_power", number_or_null(e.payload_power())},
                {"servo_power", number_or_null(e.servo_power())},
                {"generator_power", number_or_null(e.generator_power())},
                {"battery_a", battery_json(e.battery_a())},
                {"battery_b", battery_json(e.battery_b())}};
    print_json({{"topic", "energy"},
                {"vehicle", e.vehicle().to_string()},
                {"bus", e.bus().to_string()},
                {"address", e.address()},
                {"values", values}});
    return;
  }
  std::printf("%s\n", device_label(e.vehicle().to_string(), e.bus().to_string(), e.address()).c_str());
  std::printf("  %-10s %10s  %-10s %10s  %-10s %10s  %-10s %10s\n", "avionics", watts(e.avionics_power()).c_str(),
              "28 V", watts(e.output_28v_power()).c_str(), "payload", watts(e.payload_power()).c_str(), "servo",
              watts(e.servo_power()).c_str());
  std::printf("  %-10s %10s\n", "generator", watts(e.generator_power()).c_str());
  print_battery("battery A", e.battery_a());
  print_battery("battery B", e.battery_b());
}

void print_bms(const GlobalOptions& o, const pmu::v5::BmsEnergy& e) {
  if (o.json) {
    Json values{{"power", number_or_null(e.power())},
                {"used_wh", number_or_null(e.used_wh())},
                {"integrated_s", number_or_null(e.integrated_s())},
                {"endurance_s", number_or_null(e.endurance_s())},
                {"capacity_ah", number_or_null(e.capacity_ah())},
                {"critical_state_of_charge", number_or_null(e.critical_state_of_charge())}};
    print_json({{"topic", "bms_energy"},
                {"vehicle", e.vehicle().to_string()},
                {"bus", e.bus().to_string()},
                {"node", e.node()},
                {"values", values}});
    return;
  }
  const std::string vehicle = e.vehicle().to_string();
  std::printf("%s%s/battery%u\n", vehicle.empty() ? "" : (vehicle + "/").c_str(), e.bus().to_string().c_str(),
              static_cast<unsigned>(e.node()));
  std::printf("  %-10s %10s  used %8.3f Wh in %.0f s  endurance %s to %.0f %% SoC, capacity %s\n", "battery",
              watts(e.power()).c_str(), e.used_wh(), static_cast<double>(e.integrated_s()),
              duration_text(e.endurance_s()).c_str(), static_cast<double>(e.critical_state_of_charge()),
              amp_hours(e.capacity_ah()).c_str());
}

}  // namespace
}  // namespace energy_lines

void print_energy(const GlobalOptions& o, const pmu::v5::Energy& e) { energy_lines::print_pmu(o, e); }
void print_bms_energy(const GlobalOptions& o, const pmu::v5::BmsEnergy& e) { energy_lines::print_bms(o, e); }

}  // namespace pmu::tools
