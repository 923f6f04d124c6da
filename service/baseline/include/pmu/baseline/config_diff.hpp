#pragma once
// A device against a configuration file, item by item, on the raw values the wire carries.

#include <optional>
#include <string>
#include <vector>

#include "pmu/baseline/config_file.hpp"

namespace pmu::baseline {

struct Difference {
  Setting setting;
  std::optional<std::uint32_t> device;  // nullopt: the device's value has not been read
  std::uint32_t file = 0;
  int line = 0;  // the file's line of the setting
};

// Every setting the file has whose device value differs or is not known, in Setting's order.
// Settings the file leaves out are not compared (not_in_file() names them).
std::vector<Difference> differences(const Settings& device, const ConfigFile& file);

// The settings the device has and the file does not set: a diff says so, so that "equal"
// never hides a file that checks less than the reader thinks.
std::vector<Setting> not_in_file(const Settings& device, const ConfigFile& file);

// "avionics_voltage: device 24.0 V, file 22.0 V" (or "device not read").
std::string describe(const Difference& d);

}  // namespace pmu::baseline
