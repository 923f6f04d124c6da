#include "support/configured_service.hpp"

#include <unistd.h>

#include <chrono>
#include <fstream>
#include <iterator>

namespace pmu::test {

ConfiguredService::ConfiguredService(const std::string& program, const std::string& config_yaml) {
  char dir[] = "/tmp/pmu-service-test-XXXXXX";
  if (::mkdtemp(dir)) dir_ = dir;
  config_ = dir_ + "/pmu-service.yaml";
  log_ = dir_ + "/service.log";
  std::ofstream(config_) << config_yaml;
  ChildOptions o;
  o.stdout_path = o.stderr_path = log_;
  process_ = Child({program, "--config", config_}, o);
}

ConfiguredService::~ConfiguredService() {
  (void)process_.stop(std::chrono::seconds(10));
  ::unlink(config_.c_str());
  ::unlink(log_.c_str());
  ::rmdir(dir_.c_str());
}

std::string ConfiguredService::describe() {
  std::ifstream in(log_);
  return std::string(process_.running() ? "service running" : "service exited") + ", log:\n" +
         std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

}  // namespace pmu::test
