#pragma once
// A PMU's telemetry packet as the contract's sample (idl/telemetry.idl), filled in one place
// for the DDS publisher and for `pmuctl decode --mcap`, which writes the same samples' CDR
// bytes into an MCAP file without a DDS participant.

#include <cstdint>
#include <string>
#include <vector>

#include "pmu/codec/decode.hpp"
#include "pmu/idl/telemetry.h"
#include "pmu/idl_tables/device_key.hpp"

namespace pmu::service {

// The keys every sample of a device starts with (telemetry, state and battery/MPPT types).
template <class T>
void set_key(T& s, const std::string& vehicle, const DeviceKey& k) {
  s.vehicle(vehicle);
  s.bus(k.bus);
  s.address(k.address);
}

// A codec value as the IDL's float.
inline float idl_float(double v) { return static_cast<float>(v); }

// Values only; the keys are the caller's.
void fill(pmu::v5::Voltages& s, const codec::Voltages& v);
void fill(pmu::v5::Currents& s, const codec::Currents& c);
void fill(pmu::v5::BatteryEnergy& s, const codec::BatteryEnergy& e);
void fill(pmu::v5::Temperatures& s, const codec::Temperatures& t);
void fill(pmu::v5::Status& s, const codec::Status& st);

struct TelemetryCdr {
  const char* topic = nullptr;  // topics::kVoltages, ...
  // The serialized payload as a DataWriter sends it: the 4-byte encapsulation header
  // (CDR little-endian) and the body, by the generated code.
  std::vector<std::uint8_t> bytes;
};

// The sample of a telemetry packet (0x00..0x04) with its keys; false for any other packet
// and for a zero-length request. Does not throw.
bool telemetry_cdr(const std::string& vehicle, const DeviceKey& key, const codec::PmuMessage& m, TelemetryCdr& out);

}  // namespace pmu::service
