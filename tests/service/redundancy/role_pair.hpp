#pragma once
// Two role machines on a fake clock, joined as two hosts are: DDS between them (which a test can
// cut), one CAN bus (which each can lose), and each process can be killed, frozen and resumed.
// Every tick it checks, independently of the machines, that no two running instances may
// transmit at once, and that none became ACTIVE within can_silence of hearing the other's
// claim or ownership on CAN (docs/design.md, "Hot standby").

#include <chrono>
#include <functional>
#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "pmu/redundancy/role_machine.hpp"

namespace pmu::redundancy {

// A failed expectation names the role and the alarm, not their bytes.
inline void PrintTo(Role role, std::ostream* os) { *os << role_name(role); }
inline void PrintTo(PeerAlarm alarm, std::ostream* os) { *os << alarm_name(alarm); }

}  // namespace pmu::redundancy

namespace pmu::redundancy::pair_test {

inline constexpr Duration kTick{5};

struct Host {
  Settings settings;
  std::unique_ptr<RoleMachine> machine;  // none: not running (killed, or not started)
  bool frozen = false;
  BusState bus = BusState::Ok;
  std::vector<std::function<void(Time)>> queued;  // what its sockets held while it was frozen
  std::optional<Time> heard_claim;                // the peer's last CLAIMING or ACTIVE CAN frame, delivered
  Role last_role = Role::Joining;
  bool was_ever_owner_or_claimant = false;
};

class Pair {
 public:
  Pair(std::uint8_t priority_a, std::uint8_t priority_b) {
    hosts_[0].settings.priority = priority_a;
    hosts_[0].settings.peer = "b";
    hosts_[1].settings.priority = priority_b;
    hosts_[1].settings.peer = "a";
  }

  Time now() const { return now_; }
  Host& host(int i) { return hosts_[i]; }
  RoleMachine& machine(int i) { return *hosts_[i].machine; }
  Role role(int i) const { return hosts_[i].machine ? hosts_[i].machine->role() : Role::Leaving; }
  const std::vector<std::string>& violations() const { return violations_; }
  bool dds_up = true;

  void start(int i) {
    hosts_[i].machine = std::make_unique<RoleMachine>(hosts_[i].settings, now_);
    hosts_[i].frozen = false;
    hosts_[i].queued.clear();
    hosts_[i].heard_claim.reset();
    hosts_[i].last_role = Role::Joining;
    hosts_[i].was_ever_owner_or_claimant = false;
  }
  void kill(int i) { hosts_[i].machine.reset(); }
  void freeze(int i) { hosts_[i].frozen = true; }
  // `timer_first`: the holder's timer fires before it drains its sockets, so the machine is
  // polled before it hears what came during the freeze.
  void resume(int i, bool timer_first = false) {
    hosts_[i].frozen = false;
    if (timer_first) {
      const Actions a = hosts_[i].machine->poll(now_);
      check();
      send(i, a);
    }
    auto queued = std::move(hosts_[i].queued);
    hosts_[i].queued.clear();
    for (auto& event : queued) event(now_);
    check();
  }
  void set_bus(int i, BusState state) {
    hosts_[i].bus = state;
    if (running(i)) hosts_[i].machine->on_bus_state(now_, state);
  }
  bool running(int i) const { return hosts_[i].machine && !hosts_[i].frozen; }

  // Both hosts poll, then what each sent reaches the other: two decisions within one tick cross,
  // as two claims made within a frame's time do on the bus.
  void tick() {
    Actions sent[2];
    for (int i = 0; i < 2; ++i)
      if (running(i)) sent[i] = hosts_[i].machine->poll(now_);
    for (int i = 0; i < 2; ++i) send(i, sent[i]);
    check();
    now_ += kTick;
  }
  void run_for(Duration d) {
    const Time end = now_ + d;
    while (now_ < end) tick();
  }
  // The time from now until `done` holds, ticking; none if not within `limit`.
  std::optional<Duration> run_until(const std::function<bool()>& done, Duration limit) {
    const Time start = now_;
    while (now_ - start <= limit) {
      if (done()) return std::chrono::duration_cast<Duration>(now_ - start);
      tick();
    }
    return std::nullopt;
  }
  // Sends what a machine said outside a poll (a move, a leave) the way its holder would.
  void send(int from, const Actions& a) {
    const int to = 1 - from;
    if (a.dds && dds_up) {
      const DdsBeat beat = *a.dds;
      deliver(to, [this, to, beat](Time t) { hosts_[to].machine->on_peer_heartbeat(t, beat); });
    }
    if (a.can && hosts_[from].bus == BusState::Ok && hosts_[to].bus == BusState::Ok) {
      const CanBeat beat = *a.can;
      deliver(to, [this, to, beat](Time t) {
        if (beat.claim != CanClaim::Released) hosts_[to].heard_claim = t;
        hosts_[to].machine->on_peer_can(t, beat);
      });
    }
  }

 private:
  void deliver(int to, std::function<void(Time)> event) {
    if (!hosts_[to].machine) return;
    if (hosts_[to].frozen) {
      hosts_[to].queued.push_back(std::move(event));
      return;
    }
    event(now_);
  }

  void check() {
    int transmitting = 0;
    for (int i = 0; i < 2; ++i) {
      if (!running(i)) continue;
      Host& h = hosts_[i];
      const Role r = h.machine->role();
      if (h.machine->may_transmit()) ++transmitting;
      if (r == Role::Active && h.last_role != Role::Active && h.heard_claim &&
          now_ - *h.heard_claim < h.settings.can_silence)
        violations_.push_back("host " + std::to_string(i) + " became active " +
                              std::to_string(std::chrono::duration_cast<Duration>(now_ - *h.heard_claim).count()) +
                              " ms after hearing the peer on CAN");
      if (r == Role::Active || r == Role::Claiming) h.was_ever_owner_or_claimant = true;
      h.last_role = r;
    }
    if (transmitting > 1)
      violations_.push_back("both hosts may transmit at " +
                            std::to_string(std::chrono::duration_cast<Duration>(now_.time_since_epoch()).count()) +
                            " ms");
  }

  Time now_{std::chrono::hours(1)};
  Host hosts_[2];
  std::vector<std::string> violations_;
};

// Both started at once, run until one owns the bus and the other settled.
inline void settle(Pair& p) {
  p.start(0);
  p.start(1);
  p.run_for(std::chrono::seconds(2));
}

}  // namespace pmu::redundancy::pair_test
