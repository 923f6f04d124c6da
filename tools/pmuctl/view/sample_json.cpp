#include "pmuctl/view/sample_json.hpp"

#include "pmuctl/view/sample_fields.hpp"

namespace pmu::tools {

Json values_of(const pmu::v4::Voltages& s) { return json_of(fields_of(s)); }
Json values_of(const pmu::v4::Currents& s) { return json_of(fields_of(s)); }
Json values_of(const pmu::v4::BatteryEnergy& s) { return json_of(fields_of(s)); }
Json values_of(const pmu::v4::Temperatures& s) { return json_of(fields_of(s)); }
Json values_of(const pmu::v4::Status& s) { return json_of(fields_of(s)); }
Json values_of(const pmu::v4::Config& s) { return json_of(fields_of(s)); }
Json values_of(const pmu::v4::DeviceInfo& s) { return json_of(fields_of(s)); }
Json values_of(const pmu::v4::Health& s) { return json_of(fields_of(s)); }
Json values_of(const pmu::v4::Battery& s) { return json_of(fields_of(s)); }
Json values_of(const pmu::v4::BatteryCells& s) { return json_of(fields_of(s)); }
Json values_of(const pmu::v4::Mppt& s) { return json_of(fields_of(s)); }

const char* to_string(pmu::v4::HealthState s) {
  switch (s) {
    case pmu::v4::UNKNOWN: return "UNKNOWN";
    case pmu::v4::ONLINE: return "ONLINE";
    case pmu::v4::STALE: return "STALE";
    case pmu::v4::OFFLINE: return "OFFLINE";
  }
  return "UNKNOWN";
}

const char* to_string(pmu::v4::BusState s) {
  switch (s) {
    case pmu::v4::UP: return "UP";
    case pmu::v4::ERROR_WARNING: return "ERROR_WARNING";
    case pmu::v4::ERROR_PASSIVE: return "ERROR_PASSIVE";
    case pmu::v4::BUS_OFF: return "BUS_OFF";
    case pmu::v4::DOWN: return "DOWN";
  }
  return "DOWN";
}

const char* to_string(pmu::v4::DeviceKind k) {
  switch (k) {
    case pmu::v4::KIND_PMU: return "pmu";
    case pmu::v4::KIND_BATTERY: return "battery";
    case pmu::v4::KIND_MPPT: return "mppt";
  }
  return "pmu";
}

}  // namespace pmu::tools
