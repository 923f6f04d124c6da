#include "pmuctl/view/sample_json.hpp"

#include "pmuctl/view/sample_fields.hpp"

namespace pmu::tools {

Json values_of(const pmu::Voltages& s) { return json_of(fields_of(s)); }
Json values_of(const pmu::Currents& s) { return json_of(fields_of(s)); }
Json values_of(const pmu::BatteryEnergy& s) { return json_of(fields_of(s)); }
Json values_of(const pmu::Temperatures& s) { return json_of(fields_of(s)); }
Json values_of(const pmu::Status& s) { return json_of(fields_of(s)); }
Json values_of(const pmu::Config& s) { return json_of(fields_of(s)); }
Json values_of(const pmu::DeviceInfo& s) { return json_of(fields_of(s)); }
Json values_of(const pmu::Health& s) { return json_of(fields_of(s)); }
Json values_of(const pmu::Battery& s) { return json_of(fields_of(s)); }
Json values_of(const pmu::BatteryCells& s) { return json_of(fields_of(s)); }
Json values_of(const pmu::Mppt& s) { return json_of(fields_of(s)); }

const char* to_string(pmu::HealthState s) {
  switch (s) {
    case pmu::UNKNOWN: return "UNKNOWN";
    case pmu::ONLINE: return "ONLINE";
    case pmu::STALE: return "STALE";
    case pmu::OFFLINE: return "OFFLINE";
  }
  return "UNKNOWN";
}

const char* to_string(pmu::BusState s) {
  switch (s) {
    case pmu::UP: return "UP";
    case pmu::ERROR_WARNING: return "ERROR_WARNING";
    case pmu::ERROR_PASSIVE: return "ERROR_PASSIVE";
    case pmu::BUS_OFF: return "BUS_OFF";
    case pmu::DOWN: return "DOWN";
  }
  return "DOWN";
}

const char* to_string(pmu::DeviceKind k) {
  switch (k) {
    case pmu::KIND_PMU: return "pmu";
    case pmu::KIND_BATTERY: return "battery";
    case pmu::KIND_MPPT: return "mppt";
  }
  return "pmu";
}

}  // namespace pmu::tools
