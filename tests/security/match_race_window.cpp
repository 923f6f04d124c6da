// match_race_window.hpp says what this does and why.
#include "match_race_window.hpp"

#include <dlfcn.h>
#include <fastdds/rtps/builtin/data/WriterProxyData.h>

#include <condition_variable>
#include <map>
#include <mutex>

#define PMU_FASTDDS_SET_REMOTE_LOCATORS \
  "_ZN8eprosima8fastrtps4rtps15WriterProxyData19set_remote_locatorsERKNS1_17RemoteLocatorListERKNS1_14NetworkFactoryEb"

using eprosima::fastrtps::rtps::NetworkFactory;
using eprosima::fastrtps::rtps::RemoteLocatorList;
using eprosima::fastrtps::rtps::WriterProxyData;

namespace {

std::mutex m;
std::condition_variable cv;
std::map<const void*, bool> waiting;  // proxy -> a second caller came
int overlaps = 0;
int alone = 0;

// The participant stateless message writer (DDS-Security 7.4.3): the proxy
// match_builtin_endpoints fills first.
bool is_stateless_writer(const WriterProxyData& w) {
  const auto& id = w.guid().entityId.value;
  return id[0] == 0x00 && id[1] == 0x02 && id[2] == 0x01 && id[3] == 0xc3;
}

void widen(const void* proxy) {
  std::unique_lock<std::mutex> lock(m);
  const auto it = waiting.find(proxy);
  if (it != waiting.end()) {
    it->second = true;
    ++overlaps;
    cv.notify_all();
    return;
  }
  waiting[proxy] = false;
  if (!cv.wait_for(lock, pmu::security_test::kWindow, [&] { return waiting[proxy]; })) ++alone;
  waiting.erase(proxy);
}

}  // namespace

extern "C" void pmu_test_set_remote_locators(void* self, const RemoteLocatorList& l, const NetworkFactory& n,
                                             bool multicast) __asm__(PMU_FASTDDS_SET_REMOTE_LOCATORS);

extern "C" void pmu_test_set_remote_locators(void* self, const RemoteLocatorList& l, const NetworkFactory& n,
                                             bool multicast) {
  using Function = void (*)(void*, const RemoteLocatorList&, const NetworkFactory&, bool);
  static const auto next = reinterpret_cast<Function>(dlsym(RTLD_NEXT, PMU_FASTDDS_SET_REMOTE_LOCATORS));
  if (is_stateless_writer(*static_cast<const WriterProxyData*>(self))) widen(self);
  next(self, l, n, multicast);
}

namespace pmu::security_test {

int match_overlaps() {
  const std::lock_guard<std::mutex> lock(m);
  return overlaps;
}

int match_windows_alone() {
  const std::lock_guard<std::mutex> lock(m);
  return alone;
}

}  // namespace pmu::security_test
