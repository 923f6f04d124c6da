#pragma once
// systemd glue: Type=notify readiness, STATUS= lines and the watchdog. Every call is a no-op
// when not started by systemd (no $NOTIFY_SOCKET), so the same binary runs by hand.

#include <chrono>
#include <string>

namespace pmu::service {

class SystemdNotifier {
 public:
  SystemdNotifier();
  bool watchdog_enabled() const noexcept { return watchdog_ > std::chrono::microseconds::zero(); }
  // How often to feed the watchdog: half the unit's WatchdogSec.
  std::chrono::microseconds watchdog_interval() const noexcept { return watchdog_ / 2; }

  void ready(const std::string& status) const;
  void status(const std::string& status) const;
  void watchdog() const;
  void stopping() const;

 private:
  std::chrono::microseconds watchdog_{0};
};

}  // namespace pmu::service
