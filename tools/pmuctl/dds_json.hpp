#pragma once
// JSON forms of the contract's DDS samples, keyed by the contract's field names
// (interface.md), for `pmuctl --json` and for the table printer.

#include <nlohmann/json.hpp>

#include "pmu/idl/command.h"
#include "pmu/idl/state.h"
#include "pmu/idl/telemetry.h"

namespace pmu::tools {

using Json = nlohmann::ordered_json;

Json values_of(const pmu::Voltages& s);
Json values_of(const pmu::Currents& s);
Json values_of(const pmu::BatteryEnergy& s);
Json values_of(const pmu::Temperatures& s);
Json values_of(const pmu::Status& s);
Json values_of(const pmu::Config& s);
Json values_of(const pmu::DeviceInfo& s);
Json values_of(const pmu::Health& s);

const char* to_string(pmu::HealthState s);
const char* to_string(pmu::BusState s);

}  // namespace pmu::tools
