#pragma once
// What pmu-service checks before it opens a bus or the network. Every start runs it first and
// `--check-config` runs it and stops, so the two cannot disagree: the DDS-Security files
// (security_files.hpp: present, readable, valid, not expired, one CA not reused) and that their
// permissions let the service publish its dds_statistics topics, and the QoS
// profile file (dds_qos_file.hpp: found, well-formed, loaded by Fast DDS, holding every
// profile the service makes endpoints with, each with the declared capacity), and that the
// config does not ask for a hot-standby pair (`redundancy:`), which this service does not run
// as. The config's
// own checks (keys, values, documents, paths, credentials) ran when it was parsed.
// Start-up only; loads the QoS file into Fast DDS's process-wide registry.

#include <string>
#include <vector>

#include "pmu/config/config.hpp"

namespace pmu::service {

struct StartupCheck {
  std::vector<std::string> errors;    // "FILE:LINE: what is wrong"; any error stops the start
  std::vector<std::string> warnings;  // e.g. a certificate that ends within warn_days
  std::string qos_file;               // the QoS profile file the start will load
  bool ok() const noexcept { return errors.empty(); }
};

StartupCheck check_startup(const Config& cfg);

}  // namespace pmu::service
