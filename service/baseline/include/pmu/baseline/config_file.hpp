#pragma once
// The configuration file of one PMU (interface.md 4.6): what `pmuctl config snapshot` writes,
// `config diff` and `config apply` read, and a device's `baseline:` names. YAML:
//
//   device:                      where it was read; `serial` and `min_firmware` also pin a
//     vehicle: uav1              baseline to a unit and a firmware (the rest is information)
//     bus: can0
//     address: 1
//     serial: 1001
//     firmware: "1.17"
//     date: "2026-12-03T07:10:00Z"
//   parameters:                  any of the eleven stored parameters, in their units
//     avionics_voltage: 24.0
//     packets_streamed: [voltages, currents, battery_energy, temperatures, status]
//   outputs: [avionics_servo, payload]
//   generation_enabled: true
//
// Reading is total: any text gives a ConfigFile or one error with its line; nothing is
// thrown. Every value is checked against the spec (range, step, the firmware's bits) as the
// value the wire would carry, so a file that reads is one the device can take.

#include <array>
#include <optional>
#include <string>
#include <string_view>

#include "pmu/baseline/settings.hpp"
#include "pmu/codec/firmware.hpp"
#include "pmu/codec/result.hpp"

namespace pmu::baseline {

// The largest PMU configuration file read (interface.md 4.6): a full one is under 1 KiB.
inline constexpr std::size_t kMaxConfigFileBytes = std::size_t{64} << 10;
// The longest path a service's config may give as a PMU's `baseline:`: pmu/baseline's
// `file` is a string<255>.
inline constexpr std::size_t kMaxPathBytes = 255;

struct Header {
  std::string vehicle;
  std::string bus;
  std::optional<std::uint16_t> address;
  std::optional<std::uint16_t> serial;
  std::optional<codec::FirmwareVersion> firmware;
  std::optional<codec::FirmwareVersion> min_firmware;
  std::string date;
};

struct ConfigFile {
  Header header;
  Settings settings;                      // what the file sets; empty = not in the file
  std::array<int, kSettingCount> line{};  // where each setting is (1-based); 0 = not in the file
  int serial_line = 0;
  int min_firmware_line = 0;
  int line_of(Setting s) const noexcept { return line[static_cast<std::size_t>(s)]; }
};

struct FileError {
  int line = 1;  // 1-based
  std::string message;
};
// "FILE:LINE: message"
std::string describe(const FileError& e, std::string_view source);

// Reads `text`. Values are checked for the firmware the file's header names, or the current
// document's when it names none; check_firmware() checks them again for a device.
codec::Result<ConfigFile, FileError> read_config_file(std::string_view text);

// The first value of `file` that `firmware` cannot store (a power_up_state bit it lacks), as
// an error at that value's line; nullopt when every value fits.
std::optional<FileError> check_firmware(const ConfigFile& file, std::optional<codec::FirmwareVersion> firmware);

// The file text for a device: the header, then every setting `settings` has, in Setting's
// order, with a comment giving the unit. read_config_file() of it gives the same header and
// settings back.
std::string write_config_file(const Header& header, const Settings& settings);

}  // namespace pmu::baseline
