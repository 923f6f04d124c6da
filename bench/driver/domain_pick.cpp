#include "domain_pick.hpp"

#include <cstdlib>
#include <filesystem>
#include <string_view>

namespace pmu::bench {

std::set<int> domains_with_shm_ports(const std::string& shm_dir) {
  std::set<int> found;
  std::error_code ec;
  constexpr std::string_view prefix = "fastrtps_port";
  for (const auto& entry : std::filesystem::directory_iterator(shm_dir, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind(prefix, 0) != 0) continue;
    // fastrtps_port<N>, fastrtps_port<N>_el, fastrtps_port<N>_sl
    char* end = nullptr;
    const long port = std::strtol(name.c_str() + prefix.size(), &end, 10);
    if (end == name.c_str() + prefix.size() || port < first_port(0)) continue;
    found.insert(static_cast<int>((port - first_port(0)) / (first_port(1) - first_port(0))));
  }
  return found;
}

int free_domain_base(unsigned spread, const std::set<int>& taken) {
  constexpr unsigned bases = (kDomainLast - kDomainFirst + 1) / kDomainsPerRun;
  for (unsigned i = 0; i < bases; ++i) {
    const int base = kDomainFirst + static_cast<int>((spread + i) % bases) * kDomainsPerRun;
    bool free = true;
    for (int d = base; d < base + kDomainsPerRun; ++d) free = free && taken.count(d) == 0;
    if (free) return base;
  }
  return -1;
}

}  // namespace pmu::bench
