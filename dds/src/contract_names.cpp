#include "pmu/dds/contract_names.hpp"

#include <cctype>

#include "pmu/version.hpp"

namespace pmu::dds {
namespace {

constexpr std::string_view kModule = "pmu::";
// The first contract whose type names carry their version.
constexpr int kFirstVersionedContract = 4;

}  // namespace

int contract_major() noexcept { return PMU_CONTRACT_MAJOR; }

std::optional<int> contract_of_type_name(std::string_view name) {
  if (name.substr(0, kModule.size()) != kModule) return std::nullopt;
  const std::string_view rest = name.substr(kModule.size());
  const auto sep = rest.find("::");
  if (sep == std::string_view::npos)
    return rest.empty() ? std::nullopt : std::optional<int>(kFirstVersionedContract - 1);
  const std::string_view module = rest.substr(0, sep);
  if (module.size() < 2 || module.size() > 4 || module[0] != 'v' || sep + 2 >= rest.size()) return std::nullopt;
  int major = 0;
  for (const char c : module.substr(1)) {
    if (!std::isdigit(static_cast<unsigned char>(c))) return std::nullopt;
    major = major * 10 + (c - '0');
  }
  if (major < kFirstVersionedContract) return std::nullopt;
  return major;
}

std::string type_name_in_contract(std::string_view current, int major) {
  const auto own = contract_of_type_name(current);
  if (!own || *own < kFirstVersionedContract) return std::string(current);
  const std::string_view type = current.substr(current.find("::", kModule.size()) + 2);
  if (major < kFirstVersionedContract) return std::string(kModule) + std::string(type);
  return std::string(kModule) + "v" + std::to_string(major) + "::" + std::string(type);
}

std::string contract_text(int major) {
  return "contract v" + std::to_string(major) + (major < kFirstVersionedContract ? " (or older)" : "");
}

}  // namespace pmu::dds
