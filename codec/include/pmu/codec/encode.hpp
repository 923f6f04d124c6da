#pragma once
// Typed value -> frame. A value outside what the spec allows (out of range, not on the
// parameter's step, NaN, a bit the firmware does not define) gives an EncodeError, never a
// frame: nothing out of range can reach a bus through this API.
//
// Master side (what the service sends): encode_get, encode_set, encode_measurement_request,
// encode_outputs/enable/disable, encode_generation, encode_command.
// Device side (what the PMU, and so the simulator, sends): encode_voltages .. encode_status,
// encode_parameter_reply, encode_outputs_reply, encode_serial, encode_firmware.

#include <cstdint>
#include <optional>
#include <string>

#include "pmu/codec/can_frame.hpp"
#include "pmu/codec/firmware.hpp"
#include "pmu/codec/ids.hpp"
#include "pmu/codec/messages.hpp"
#include "pmu/codec/result.hpp"

namespace pmu::codec {

enum class EncodeErrorKind : std::uint8_t {
  NotANumber,   // NaN or infinity
  OutOfRange,   // outside [min, max]
  NotOnStep,    // between two representable values (e.g. 12.05 V with 0.1 V steps)
  InvalidBits,  // a mask with bits the packet does not define
  Unsupported,  // the device's firmware lacks the feature
  NotAGet,      // zero-length get requested for a packet that has none
  EmptyMask,    // enable/disable with no output named
};

struct EncodeError {
  EncodeErrorKind kind = EncodeErrorKind::OutOfRange;
  std::string_view field;   // parameter or field name, e.g. "avionics_voltage"
  std::string_view unit;    // "V", "s", "" ...
  double value = 0;         // the offending value
  double min = 0, max = 0;  // allowed range (OutOfRange, NotOnStep)
  std::uint32_t bits = 0;   // allowed bits (InvalidBits, Unsupported)
  std::optional<FirmwareVersion> firmware;
  std::optional<FirmwareVersion> needs;  // first firmware with the feature (Unsupported)

  // "value 30.0 V out of range 12.0..24.0 V for avionics_voltage"
  std::string describe() const;
};

using Encoded = Result<CanFrame, EncodeError>;

// ---- master side -----------------------------------------------------------------------
Encoded encode_get(PacketId packet, std::uint16_t address) noexcept;
// Engineering value (V, s, degC, number, mask); validated against the spec's range, its step
// and, for S0, the bits the firmware defines.
Encoded encode_set(Parameter p, double value, std::uint16_t address,
                   std::optional<FirmwareVersion> fw = std::nullopt) noexcept;
Encoded encode_measurement_request(std::uint8_t groups, std::uint16_t address,
                                   std::optional<FirmwareVersion> fw = std::nullopt) noexcept;
Encoded encode_set_outputs(std::uint8_t mask, std::uint16_t address) noexcept;
Encoded encode_enable_outputs(std::uint8_t mask, std::uint16_t address) noexcept;
Encoded encode_disable_outputs(std::uint8_t mask, std::uint16_t address) noexcept;
Encoded encode_generation(bool enabled, std::uint16_t address) noexcept;
Encoded encode_engine_start(std::uint16_t address) noexcept;
Encoded encode_engine_stop(std::uint16_t address) noexcept;
Encoded encode_reset(std::uint16_t address) noexcept;

// Raw form of a parameter value: validates like encode_set but in wire units.
Result<std::uint32_t, EncodeError> to_raw(Parameter p, double value,
                                          std::optional<FirmwareVersion> fw = std::nullopt) noexcept;

// ---- device side -----------------------------------------------------------------------
Encoded encode_voltages(const Voltages& v, std::uint16_t address) noexcept;
Encoded encode_currents(const Currents& c, std::uint16_t address) noexcept;
Encoded encode_battery_energy(const BatteryEnergy& e, std::uint16_t address) noexcept;
Encoded encode_temperatures(const Temperatures& t, std::uint16_t address) noexcept;
// Bit 6 of flag register 0 comes from soa_shutdown or start_button as `fw` dictates.
Encoded encode_status(const Status& s, std::uint16_t address,
                      std::optional<FirmwareVersion> fw = std::nullopt) noexcept;
// A stored value as the PMU reports it; the raw value only needs to fit the field's width
// (a device may hold a value no set could write).
Encoded encode_parameter_reply(Parameter p, std::uint32_t raw, std::uint16_t address) noexcept;
Encoded encode_outputs_reply(std::uint8_t mask, std::uint16_t address) noexcept;
Encoded encode_generation_reply(bool enabled, std::uint16_t address) noexcept;
Encoded encode_serial(std::uint16_t serial, std::uint16_t address) noexcept;
Encoded encode_firmware(const FirmwareInfo& f, std::uint16_t address) noexcept;

}  // namespace pmu::codec
