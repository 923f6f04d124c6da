#include "pmu/baseline/config_diff.hpp"

namespace pmu::baseline {

std::vector<Difference> differences(const Settings& device, const ConfigFile& file) {
  std::vector<Difference> out;
  for (std::size_t i = 0; i < kSettingCount; ++i) {
    const auto s = static_cast<Setting>(i);
    const auto& want = file.settings[s];
    if (!want) continue;
    const auto& have = device[s];
    if (have && *have == *want) continue;
    out.push_back({s, have, *want, file.line_of(s)});
  }
  return out;
}

std::vector<Setting> not_in_file(const Settings& device, const ConfigFile& file) {
  std::vector<Setting> out;
  for (std::size_t i = 0; i < kSettingCount; ++i) {
    const auto s = static_cast<Setting>(i);
    if (device[s] && !file.settings[s]) out.push_back(s);
  }
  return out;
}

std::string describe(const Difference& d) {
  return std::string(setting_name(d.setting)) + ": device " +
         (d.device ? value_text(d.setting, *d.device) : std::string("not read")) + ", file " +
         value_text(d.setting, d.file);
}

}  // namespace pmu::baseline
