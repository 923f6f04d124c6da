#pragma once
// pmu::test_support: a pmu-service process on a config of the test's own.
//
// ConfiguredService writes `config_yaml` to pmu-service.yaml in a new folder under /tmp, starts
// `program --config THAT` with stdout and stderr in service.log beside it, and on destruction
// stops it (SIGTERM, as Child does) and removes the folder's files. describe() is for failure
// messages: whether it still runs and everything it logged.
//
//   pmu::test::ConfiguredService service(PMU_SERVICE_PATH, "domain: 7\nbuses: ...");
//   EXPECT_TRUE(...) << service.describe();
//
// Start it from the test's main thread (Child's rule).
#include <string>

#include "support/process.hpp"

namespace pmu::test {

class ConfiguredService {
 public:
  ConfiguredService(const std::string& program, const std::string& config_yaml);
  ~ConfiguredService();
  ConfiguredService(const ConfiguredService&) = delete;
  ConfiguredService& operator=(const ConfiguredService&) = delete;

  std::string describe();
  // The service's process (to stop or kill it as a test's fault).
  pid_t pid() const { return process_.pid(); }

 private:
  std::string dir_, config_, log_;
  Child process_;
};

}  // namespace pmu::test
