#include "pmu/app/systemd.hpp"

#include <systemd/sd-daemon.h>

#include <cstdint>

namespace pmu::service {

SystemdNotifier::SystemdNotifier() {
  std::uint64_t usec = 0;
  if (sd_watchdog_enabled(0, &usec) > 0) watchdog_ = std::chrono::microseconds(usec);
}

void SystemdNotifier::ready(const std::string& status) const { sd_notifyf(0, "READY=1\nSTATUS=%s", status.c_str()); }
void SystemdNotifier::status(const std::string& status) const { sd_notifyf(0, "STATUS=%s", status.c_str()); }
void SystemdNotifier::watchdog() const { sd_notify(0, "WATCHDOG=1"); }
void SystemdNotifier::stopping() const { sd_notify(0, "STOPPING=1\nSTATUS=stopping"); }

}  // namespace pmu::service
