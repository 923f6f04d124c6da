// security_match_guard.hpp says why. Both definitions keep Fast DDS 2.9.1's signatures: a
// `this` pointer and a `const ParticipantProxyData&`, neither looked into here.
#include "pmu/dds/security_match_guard.hpp"

#include <dlfcn.h>

#include <mutex>

#define PMU_FASTDDS_MATCH_BUILTIN \
  "_ZN8eprosima8fastrtps4rtps8security15SecurityManager23match_builtin_endpointsERKNS1_20ParticipantProxyDataE"
#define PMU_FASTDDS_MATCH_KEY_EXCHANGE                                                                \
  "_ZN8eprosima8fastrtps4rtps8security15SecurityManager36match_builtin_key_exchange_endpointsERKNS1_" \
  "20ParticipantProxyDataE"

namespace {

using MatchFunction = void (*)(void* security_manager, const void* participant_data);

// The library's definition: the next one after this program's in the lookup order. Only
// Fast DDS calls these names, so the library that calls them defines them.
MatchFunction next_definition(const char* name) { return reinterpret_cast<MatchFunction>(dlsym(RTLD_NEXT, name)); }

void call_serialised(std::mutex& m, MatchFunction f, void* self, const void* data) {
  const std::lock_guard<std::mutex> lock(m);
  f(self, data);
}

}  // namespace

// Fast DDS's names, so that the library's calls come here (security_match_guard.hpp).
extern "C" void pmu_fastdds_match_builtin(void* self, const void* data) __asm__(PMU_FASTDDS_MATCH_BUILTIN);
extern "C" void pmu_fastdds_match_key_exchange(void* self, const void* data) __asm__(PMU_FASTDDS_MATCH_KEY_EXCHANGE);

extern "C" void pmu_fastdds_match_builtin(void* self, const void* data) {
  static std::mutex m;
  static const MatchFunction f = next_definition(PMU_FASTDDS_MATCH_BUILTIN);
  call_serialised(m, f, self, data);
}

extern "C" void pmu_fastdds_match_key_exchange(void* self, const void* data) {
  static std::mutex m;
  static const MatchFunction f = next_definition(PMU_FASTDDS_MATCH_KEY_EXCHANGE);
  call_serialised(m, f, self, data);
}

namespace pmu::dds {

bool security_match_guard_active() noexcept {
  return dlsym(RTLD_DEFAULT, PMU_FASTDDS_MATCH_BUILTIN) == reinterpret_cast<void*>(&pmu_fastdds_match_builtin) &&
         dlsym(RTLD_DEFAULT, PMU_FASTDDS_MATCH_KEY_EXCHANGE) ==
             reinterpret_cast<void*>(&pmu_fastdds_match_key_exchange) &&
         dlsym(RTLD_NEXT, PMU_FASTDDS_MATCH_BUILTIN) != nullptr &&
         dlsym(RTLD_NEXT, PMU_FASTDDS_MATCH_KEY_EXCHANGE) != nullptr;
}

}  // namespace pmu::dds
