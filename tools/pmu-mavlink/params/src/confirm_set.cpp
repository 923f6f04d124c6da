#include "pmu/mavlink_params/confirm_set.hpp"

#include "pmu/command/command.hpp"

namespace pmu::mavlink_params {

codec::Result<ConfirmSet, std::string> confirm_set(const std::vector<std::string>& names) {
  ConfirmSet set{};
  for (const auto& name : names) {
    const auto rule = service::confirm_rule_from_name(name);
    if (!rule)
      return codec::Unexpected{"unknown confirm rule '" + service::printable(name) +
                               "' (rules: " + service::confirm_rule_names() + ")"};
    set[static_cast<std::size_t>(*rule)] = true;
  }
  return set;
}

}  // namespace pmu::mavlink_params
