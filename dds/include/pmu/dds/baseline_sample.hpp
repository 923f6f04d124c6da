#pragma once
// pmu/baseline's sample (idl/state.idl, interface.md 1.9) from a configured PMU's `baseline:`,
// and back: the service writes it, `pmuctl config diff` without a file reads it and compares
// the device's pmu/config with it by pmu::baseline's rules, on the wire's values.

#include <cstdint>
#include <optional>
#include <string>

#include "pmu/baseline/config_file.hpp"
#include "pmu/idl/state.h"

namespace pmu::service {

// The PMU at `address` on `bus`: `file` is its `baseline:` path as the config writes it (at
// most baseline::kMaxPathBytes, which the config checks), `content` the file as read; a
// sample without `content` has the key and the path only.
pmu::v5::Baseline baseline_sample(const std::string& vehicle, const std::string& bus, std::uint16_t address,
                                  const std::string& file, const std::optional<baseline::ConfigFile>& content);

// What the sample holds, as read_config_file() would have given it: the settings `present`
// names, as raw values, and the serial and minimum firmware pins. Lines are 0 (not a file's).
baseline::ConfigFile config_file_of(const pmu::v5::Baseline& sample);

// pmu/config's values as raw values; every setting is there.
baseline::Settings settings_of(const pmu::v5::Config& config);

}  // namespace pmu::service
