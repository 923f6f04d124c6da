#pragma once
// `baseline:` of a PMU entry (interface.md 4.1): the configuration file the unit's settings
// are watched against, read and checked with the config so that a config that starts has a
// baseline that compares. Private to config.cpp: it takes yaml-cpp nodes, which no header of
// the room shows.

#include <yaml-cpp/yaml.h>

#include <string>

#include "pmu/config/config.hpp"

namespace pmu::service {

// `n` is the value of a device's `baseline:` key; `d`'s min_firmware is read already. Sets
// d.baseline, d.baseline_file and d.baseline_path. A relative path is taken relative to the
// folder of `source` (the config file). Throws ConfigError "SOURCE:LINE: ..." at `n` when the
// path is not one, the file cannot be read, or pmu::baseline refuses it (then with the
// baseline's own "FILE:LINE: ..." quoted).
void read_baseline(const YAML::Node& n, const std::string& source, DeviceConfig& d);

}  // namespace pmu::service
