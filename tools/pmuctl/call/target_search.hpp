#pragma once
// Which PMU a command without --bus and --address is for: the vehicle's one PMU, as its
// pmu/health instances say.
//
// The service's health is TRANSIENT_LOCAL: all of it comes in one burst once matched, so the
// search settles a quiet time after its first sample. A PMU whose CAN address changed
// (a verified `can_address` set, or a unit found at another address) is one unit with two
// keys for a moment: the service reports the old key OFFLINE and disposes it a moment later
// (DeviceSession::kGoneDelay, 250 ms), while the new key is already ONLINE. A search whose
// quiet time ends in between would see two PMUs and refuse the command as ambiguous; so
// while more than one PMU is seen and one of them has just gone OFFLINE, it waits for that
// key's disposal, up to `gone_wait` after the OFFLINE sample. A second PMU that is really
// there and offline then costs that wait once before the command is refused as ambiguous.
//
//   TargetSearch s(300ms, 1s);
//   s.seen({bus, address}, offline, now);   // each valid sample of a PMU the command may mean
//   s.gone({bus, address});                  // its instance disposed or unregistered
//   s.start(now);                            // the first sample of the vehicle's service
//   if (s.settled(now)) ... s.pmus()
//
// A plain value: used by one thread, the verb's.

#include <chrono>
#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <utility>

namespace pmu::tools {

class TargetSearch {
 public:
  using Clock = std::chrono::steady_clock;
  using Pmu = std::pair<std::string, std::uint16_t>;  // bus, CAN address

  TargetSearch(Clock::duration quiet, Clock::duration gone_wait) : quiet_(quiet), gone_wait_(gone_wait) {}

  void seen(const Pmu& pmu, bool offline, Clock::time_point now) {
    auto& since = pmus_[pmu];
    if (!offline)
      since.reset();
    else if (!since)
      since = now;
  }
  void gone(const Pmu& pmu) { pmus_.erase(pmu); }
  // The first sample of the vehicle's service, of a PMU meant or not: later calls keep it.
  void start(Clock::time_point now) {
    if (!started_) started_ = now;
  }

  bool settled(Clock::time_point now) const {
    if (!started_ || now - *started_ < quiet_) return false;
    if (pmus_.size() < 2) return true;
    for (const auto& [pmu, offline_since] : pmus_)
      if (offline_since && now - *offline_since < gone_wait_) return false;
    return true;
  }

  std::set<Pmu> pmus() const {
    std::set<Pmu> out;
    for (const auto& [pmu, offline_since] : pmus_) out.insert(pmu);
    return out;
  }

 private:
  Clock::duration quiet_;
  Clock::duration gone_wait_;
  std::optional<Clock::time_point> started_;
  std::map<Pmu, std::optional<Clock::time_point>> pmus_;  // each PMU seen: since when OFFLINE
};

}  // namespace pmu::tools
