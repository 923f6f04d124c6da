#pragma once
// Ownership: what follows the bus's ownership in pmu-service (docs/design.md, "Hot standby").
// From the change that makes this instance the bus owner, the state gate is open, commands and
// acknowledgements are executed, and what the former owner left is settled (`took_over`); from
// the change that ends it, neither. A change of the peer alarm alone changes nothing here.
// executing() also asks the holder whether its machine was judged recently enough to still own
// the bus (RoleHolder::owns_bus): a DDS listener of an owner frozen for longer than the lease
// runs, on waking, before the bus's thread has dropped the role, and must not answer then.
//
// Threads: on_change() where RoleHolder::Outputs::changed is called (the bus thread);
// executing() from any thread; judge_with() once, before any executing() call.
// Lifetime: `gate`, and the holder and clock given to judge_with(), must outlive it.

#include <atomic>
#include <functional>

#include "pmu/standby/role_gate.hpp"
#include "pmu/standby/role_holder.hpp"
#include "pmu/transport/clock.hpp"

namespace pmu::standby {

class Ownership {
 public:
  Ownership(RoleGate& gate, std::function<void()> took_over);

  // The holder whose changes on_change() receives (made after this, as its outputs call it).
  void judge_with(const RoleHolder& holder, const transport::Clock& clock);
  void on_change(const RoleChange& change);
  // The command and acknowledgement services' gate: this instance owns the bus, and its
  // machine has been told the time within the freeze gap.
  bool executing() const;

 private:
  RoleGate& gate_;
  std::function<void()> took_over_;
  std::atomic<bool> executing_{false};
  const RoleHolder* holder_ = nullptr;
  const transport::Clock* clock_ = nullptr;
};

}  // namespace pmu::standby
