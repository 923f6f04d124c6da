#pragma once
// The key of a device's samples beside the vehicle (bus, address, kind: interface.md 1.2,
// 1.4): what the service keys its sessions by and the DDS core writes into every sample, and
// what pmuctl fills when it makes samples without a service. Plain data; any thread.

#include <cstdint>
#include <string>

namespace pmu::service {

// What a device on a bus is. PMUs are addressed by CAN address; a battery by its CANopen
// node, an MPPT by its device id (0..7): the three number ranges overlap, so the kind is part
// of every device's key (pmu/health's `kind`).
enum class DeviceKind : std::uint8_t { Pmu, Battery, Mppt };

struct DeviceKey {
  std::string bus;
  std::uint16_t address = 0;  // PMU: CAN address; battery: CANopen node; MPPT: device id
  DeviceKind kind = DeviceKind::Pmu;
  friend bool operator==(const DeviceKey& a, const DeviceKey& b) {
    return a.bus == b.bus && a.address == b.address && a.kind == b.kind;
  }
};

}  // namespace pmu::service
