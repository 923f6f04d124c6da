#include "pmu/standby/ownership.hpp"

#include <utility>

namespace pmu::standby {

Ownership::Ownership(RoleGate& gate, std::function<void()> took_over) : gate_(gate), took_over_(std::move(took_over)) {}

void Ownership::judge_with(const RoleHolder& holder, const transport::Clock& clock) {
  holder_ = &holder;
  clock_ = &clock;
}

bool Ownership::executing() const {
  if (!executing_.load()) return false;
  return holder_ == nullptr || holder_->owns_bus(clock_->steady_now());
}

void Ownership::on_change(const RoleChange& change) {
  if (change.took_bus()) {
    // The state first, so that the takeover's first writes follow what was kept; then the
    // commands, the recorded ones before any new one.
    gate_.open();
    executing_.store(true);
    if (took_over_) took_over_();
  }
  if (change.left_bus()) {
    executing_.store(false);
    gate_.close();
  }
}

}  // namespace pmu::standby
