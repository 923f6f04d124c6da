#pragma once
// Ownership: what follows the bus's ownership in pmu-service (docs/design.md, "Hot standby").
// From the change that makes this instance the bus owner, the state gate is open, commands and
// acknowledgements are executed, and what the former owner left is settled (`took_over`); from
// the change that ends it, neither. A change of the peer alarm alone changes nothing here.
//
// Threads: on_change() where RoleHolder::Outputs::changed is called (the bus thread);
// executing() from any thread. Lifetime: `gate` must outlive it.

#include <atomic>
#include <functional>

#include "pmu/standby/role_gate.hpp"
#include "pmu/standby/role_holder.hpp"

namespace pmu::standby {

class Ownership {
 public:
  Ownership(RoleGate& gate, std::function<void()> took_over);

  void on_change(const RoleChange& change);
  // The command and acknowledgement services' gate: this instance owns the bus.
  bool executing() const noexcept { return executing_.load(); }

 private:
  RoleGate& gate_;
  std::function<void()> took_over_;
  std::atomic<bool> executing_{false};
};

}  // namespace pmu::standby
