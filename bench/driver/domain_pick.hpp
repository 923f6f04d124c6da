#pragma once
// Which four DDS domains a pmu_bench run takes. A Fast DDS process that is killed leaves its
// shared-memory ports in /dev/shm (fastrtps_port<N>, N = 7400 + 250 * domain + offset), and
// a stale discovery port keeps the next SHM-only participants of that domain from matching
// each other for many seconds. So a run takes domains with no such port, live or left over.

#include <set>
#include <string>

namespace pmu::bench {

inline constexpr int kDomainFirst = 150;  // pmu_bench's range, not handed to tests
inline constexpr int kDomainLast = 229;   // (tests/support/domain.hpp)
inline constexpr int kDomainsPerRun = 4;

// Fast DDS's default port mapping: a domain's ports are first_port .. first_port + 249.
constexpr int first_port(int domain) { return 7400 + 250 * domain; }

// The domains that have a Fast DDS shared-memory port file in `shm_dir`.
std::set<int> domains_with_shm_ports(const std::string& shm_dir);

// The first base whose kDomainsPerRun domains are none of `taken`, searching the range's bases
// from the one `spread` (any number, e.g. the pid) picks and wrapping round; -1 when every
// base has one. Runs at once with different spreads start at different bases.
int free_domain_base(unsigned spread, const std::set<int>& taken);

}  // namespace pmu::bench
