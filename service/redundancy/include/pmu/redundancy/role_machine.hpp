#pragma once
// Which instance of a hot-standby pair owns the CAN bus (docs/design.md, "Hot standby").
//
// Pure and single-threaded: the holder (one thread; the machine keeps no reference and has no
// lock) hands it every input with the steady time it was seen, calls poll() at least every
// poll_period(settings), and before every CAN transmission or command execution asks
// may_transmit() after a call made at that moment: a holder that was frozen learns on that
// call that it no longer owns the bus.
//
// Guarantees, kept here and shown by tests/service/redundancy/role_machine_test.cpp:
//  - it becomes ACTIVE only when no CAN heartbeat of the peer (other than its release) was seen
//    within can_silence, after having listened that long: never a second bus owner while the
//    peer is heard on the bus, even when DDS between the hosts is cut;
//  - each claim carries a term one above the highest seen; an ACTIVE or CLAIMING instance that
//    sees a stronger claim (higher term; equal term and higher priority) steps down on that call;
//  - a pause of its calls longer than freeze_gap(settings) drops every role but NO_BUS and
//    LEAVING to JOINING, forgetting what it knew of the peer;
//  - priority decides only between instances of which none owns the bus.

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>

#include "pmu/redundancy/can_beat.hpp"
#include "pmu/redundancy/role.hpp"
#include "pmu/redundancy/settings.hpp"

namespace pmu::redundancy {

using Time = std::chrono::steady_clock::time_point;

// What to send now. The DDS beat is due every heartbeat_period and at once on a change; the
// CAN beat every can_heartbeat_period while CLAIMING or ACTIVE, at once on a change or to answer
// a weaker claim, and once, marked released, when the bus is handed over.
struct Actions {
  std::optional<DdsBeat> dds;
  std::optional<CanBeat> can;
};

struct MoveResult {
  bool accepted = false;
  std::string reason;  // why not, when refused
};

class RoleMachine {
 public:
  // The instance's start: JOINING, listening from `now`. `settings` must pass settings_problem().
  RoleMachine(const Settings& settings, Time now);

  void on_peer_heartbeat(Time now, const DdsBeat& beat);
  void on_peer_can(Time now, const CanBeat& beat);
  void on_bus_state(Time now, BusState state);
  // SIGTERM: stop transmitting at once; an owner sends its release once.
  void leave(Time now);
  // A move of the role (pmuctl): an ACTIVE instance hands the bus to a live STANDBY peer and
  // stays up as STANDBY; refused, with the reason, otherwise.
  MoveResult hand_over(Time now);
  Actions poll(Time now);

  Role role() const noexcept { return role_; }
  // PMU frames on CAN and command execution: the bus owner only.
  bool may_transmit() const noexcept { return role_ == Role::Active; }
  bool executes_commands() const noexcept { return role_ == Role::Active; }
  // Whether the machine, asked at `now` from another thread than its caller's, still owns the
  // bus: ACTIVE, and called within freeze_gap. Longer without a call, its next call drops the
  // role, and what the instance does outside that call (a DDS listener answering a request)
  // must not act on a role it may have lost while it was frozen.
  bool owns_at(Time now) const noexcept { return role_ == Role::Active && now - last_call_ <= freeze_gap(settings_); }
  // The contract's state topics: the bus owner only; every instance writes pmu/role.
  bool publishes_state() const noexcept { return role_ == Role::Active; }
  std::uint32_t term() const noexcept { return term_; }
  PeerAlarm alarm() const noexcept { return alarm_; }

 private:
  void enter(Time now);
  void step(Time now);
  void set_role(Role role);
  void start_listening(Time now);
  bool stronger(std::uint32_t term, std::uint8_t priority) const noexcept;
  bool peer_dds_fresh(Time now) const noexcept;
  bool peer_dds_absent(Time now) const noexcept;
  bool peer_can_recent(Time now) const noexcept;
  bool peer_can_quiet(Time now) const noexcept;
  bool peer_holds_on_dds(Time now) const noexcept;
  bool peer_claims_stronger(Time now) const noexcept;
  Role passive_role(Time now) const noexcept;
  PeerAlarm judge_alarm(Time now) const noexcept;

  Settings settings_;
  Role role_ = Role::Joining;
  BusState bus_ = BusState::Ok;
  std::uint32_t term_ = 0;      // the term of this instance's last claim
  std::uint32_t max_term_ = 0;  // the highest term seen, its own included
  Time last_call_;
  Time listening_since_;
  std::optional<Time> dds_seen_;
  DdsBeat dds_last_;
  std::optional<Time> can_seen_;
  CanBeat can_last_;
  Time claim_start_;
  bool deferring_ = false;        // handed the bus over: claims over a passive peer by priority no more
  bool release_pending_ = false;  // the release frame is still to be sent
  bool answer_claim_ = false;     // a weaker claim was seen: send our beat at once
  bool changed_ = true;           // role, term or alarm changed since the last DDS beat
  std::optional<Time> dds_sent_;
  std::optional<Time> can_sent_;
  std::optional<CanClaim> can_claim_sent_;  // what the last CAN beat said
  PeerAlarm alarm_ = PeerAlarm::None;
};

}  // namespace pmu::redundancy
