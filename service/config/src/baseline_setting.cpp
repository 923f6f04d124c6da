#include "baseline_setting.hpp"

#include "pmu/files/bounded_file.hpp"

namespace pmu::service {
namespace {

[[noreturn]] void refuse(const YAML::Node& at, const std::string& source, const std::string& what) {
  const int line = at.IsDefined() && at.Mark().line >= 0 ? at.Mark().line + 1 : 1;
  throw ConfigError(source + ":" + std::to_string(line) + ": " + what);
}

std::string folder_of(const std::string& source) {
  const auto slash = source.rfind('/');
  return slash == std::string::npos ? std::string() : source.substr(0, slash + 1);
}

}  // namespace

void read_baseline(const YAML::Node& n, const std::string& source, DeviceConfig& d) {
  if (!n.IsScalar() || n.Scalar().empty()) refuse(n, source, "baseline must be the path of a PMU configuration file");
  d.baseline_file = n.Scalar();
  if (d.baseline_file.size() > baseline::kMaxPathBytes)
    refuse(n, source,
           "baseline: the path is " + std::to_string(d.baseline_file.size()) + " bytes long; at most " +
               std::to_string(baseline::kMaxPathBytes) + " (pmu/baseline carries it)");
  // Relative to the config file, as qos_file: systemd runs the service in /.
  d.baseline_path = d.baseline_file.front() == '/' ? d.baseline_file : folder_of(source) + d.baseline_file;
  // Regular and bounded: /dev/zero or a FIFO named here must not stop the start (docs/safety.md H12).
  const auto text = files::read_bounded_file(d.baseline_path, baseline::kMaxConfigFileBytes);
  if (!text.ok()) refuse(n, source, "baseline " + d.baseline_path + " cannot be read: " + text.error);
  auto file = baseline::read_config_file(text.text);
  if (!file) refuse(n, source, "baseline refused: " + baseline::describe(file.error(), d.baseline_path));
  // The unit is at least the higher of the two minimums, so every value must fit that
  // firmware; with neither, read_config_file has checked them for the file's own firmware.
  auto minimum = d.min_firmware;
  if (const auto& pin = file->header.min_firmware; pin && (!minimum || pin->ordinal() > minimum->ordinal()))
    minimum = pin;
  if (minimum)
    if (const auto e = baseline::check_firmware(*file, minimum))
      refuse(n, source,
             "baseline refused: " + baseline::describe(*e, d.baseline_path) + " (for firmware " +
                 codec::to_string(*minimum) + ", the device's min_firmware)");
  d.baseline = std::move(*file);
}

}  // namespace pmu::service
