#pragma once
// Configuration of a simulated Millswood 250W PMU (protocol v1.9, v1.2 for older firmware):
// what the unit is (DeviceConfig: identity, firmware, stored parameters), the world around
// it (Plant: batteries, loads, engine, temperatures) and the faults to inject (Faults).
// Plain data only; PmuModel (pmu_model.hpp) owns the behaviour.

#include <array>
#include <chrono>
#include <cstdint>
#include <optional>

#include "pmu/codec/firmware.hpp"
#include "pmu/codec/ids.hpp"
#include "pmu/codec/messages.hpp"
#include "pmu/codec/parameters.hpp"

namespace pmu::sim {

// The model never reads a clock: every call is given `now` (docs/design.md: the clock is
// injected).
using Clock = std::chrono::steady_clock;
using TimePoint = Clock::time_point;
using Duration = Clock::duration;

// The stored (non-volatile) parameters 0x10..0x1B as raw wire values (table 1, green rows),
// indexed by codec::Parameter so the codec's parameter table stays the single source of
// names, widths and ranges.
class StoredParameters {
 public:
  // Factory values. The spec fixes only CA = 1 (section 4.3); the rest are plausible choices:
  // V_A 12.0 V, V_P 12.0 V, V_S 6.0 V, V_B 25.2 V (6S Li-ion), PP 1.0 s, PS 0x1F (stream
  // everything, so a bench unit is visibly alive), T0 128, T_U 80 degC, S0 0x0F (all
  // outputs and chargers on at power-up), CT 5.0 s.
  StoredParameters() noexcept;

  std::uint32_t raw(codec::Parameter p) const noexcept;
  // No validation: a harness may preload anything the field can hold, as a real unit may
  // hold a value no set could write (codec::encode_parameter_reply accepts it too).
  void set_raw(codec::Parameter p, std::uint32_t raw) noexcept;

 private:
  std::array<std::uint32_t, codec::kParameterCount> raw_{};
};

struct BuildDate {  // packet 0x31, table 24
  std::uint16_t year = 2023;
  std::uint8_t month = 6;
  std::uint8_t day = 15;
};

struct DeviceConfig {
  // The unit's CAN address at power-up; written into the stored CA (0x1B), so it wins over
  // `parameters`' CA. 0xFFFF (broadcast) is not a device address and makes PmuModel throw.
  std::uint16_t address = codec::kDefaultAddress;
  std::uint16_t serial_number = 1;
  // Supported behaviour differences (v1.9 section 6): 1.12 external temperatures and the
  // starter-ready flag, 1.14 packet 0x0F, 1.15 S0 bit 4, 1.16 S0 bit 6 and flag register 0
  // bit 6 = SOA shutdown (start button before). 1.17 only adds baud rates (no model change).
  codec::FirmwareVersion firmware = codec::kCurrentFirmware;
  BuildDate build_date{};
  StoredParameters parameters{};
};

// The physical world the PMU measures. All values SI (V, A, degC, rpm). Values outside a
// telemetry field's range are clamped when encoded, never rejected.
struct Plant {
  double battery_a_voltage = 22.2;  // V, terminal voltage
  double battery_b_voltage = 22.2;
  double output_28v_voltage = 28.0;  // V on the 28 V output while the generator supplies it
  double generator_voltage = 48.0;   // V while the engine runs and generation is on

  // Current each output draws while enabled (A). The 28 V output is not switchable.
  double avionics_load = 1.0;
  double payload_load = 2.0;
  double servo_load = 0.5;
  double output_28v_load = 1.0;
  // Current into each battery whose charger is enabled while the generator supplies power.
  double charge_current = 2.0;

  double internal_temperature = 35.0;  // degC; compared with T_U for thermal shutdown
  double starter_temperature = 25.0;
  // External sensors (firmware 1.12+); NaN = no sensor fitted (-128 on the wire).
  double battery_a_temperature = 25.0;
  double battery_b_temperature = 25.0;
  double generator_temperature = codec::kNoSensor;

  std::uint16_t engine_rpm = 6000;   // generator speed while running with generation on
  std::uint16_t cranking_rpm = 300;  // generator speed while the starter turns the engine
  // How long cranking takes before the engine fires; nullopt = it never starts (a flooded
  // engine), so only CT or 0x25 ends the cranking.
  std::optional<Duration> engine_starts_after = std::chrono::seconds(2);

  bool starter_ready = true;  // flag register 1 bit 7 (firmware 1.12+)
  bool start_button = false;  // flag register 0 bit 6 before firmware 1.16
  bool soa_shutdown = false;  // flag register 0 bit 6 from firmware 1.16
  bool payload_shed = false;  // flag register 0 bit 7
};

// Faults a test or a bench operator can inject.
struct Faults {
  // The unit is off the bus (cable cut, dead transceiver): incoming frames are not acted
  // on, nothing is answered or streamed. The unit itself keeps running (energies integrate).
  bool silent = false;
  // Each outgoing frame is dropped with this probability, drawn from a generator seeded
  // with `loss_seed` (reseeded by every PmuModel::set_faults, so runs are reproducible).
  double loss_probability = 0.0;
  std::uint64_t loss_seed = 1;
  // Outgoing frames are held this long and released, in order, by tick().
  Duration delay{};
  // Telemetry (0x00..0x04, streamed or requested) goes out with this data length instead of
  // the spec's (capped at 8; bytes past the real payload are zero).
  std::optional<std::uint8_t> telemetry_length;
  // A unit whose memory does not take this stored parameter: a set of it is acknowledged by
  // nothing and changes nothing, so a read-back shows the old value (a worn EEPROM cell).
  std::optional<codec::Parameter> ignored_set;
};

}  // namespace pmu::sim
