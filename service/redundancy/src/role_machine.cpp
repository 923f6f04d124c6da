#include "pmu/redundancy/role_machine.hpp"

#include <algorithm>

namespace pmu::redundancy {

RoleMachine::RoleMachine(const Settings& settings, Time now)
    : settings_(settings), last_call_(now), listening_since_(now), claim_start_(now) {}

void RoleMachine::enter(Time now) {
  // The peer decides on what it last heard from us: after a pause longer than freeze_gap it may
  // be claiming or own the bus, and what we knew of it is older than its decision. So an owner
  // that wakes up stops transmitting on this very call and learns the bus anew.
  if (now - last_call_ > freeze_gap(settings_) && role_ != Role::NoBus && role_ != Role::Leaving) {
    dds_seen_.reset();
    can_seen_.reset();
    answer_claim_ = false;
    start_listening(now);
    set_role(Role::Joining);
  }
  last_call_ = std::max(last_call_, now);
}

void RoleMachine::start_listening(Time now) { listening_since_ = now; }

void RoleMachine::set_role(Role role) {
  if (role == role_) return;
  role_ = role;
  changed_ = true;
}

bool RoleMachine::stronger(std::uint32_t term, std::uint8_t priority) const noexcept {
  return term > term_ || (term == term_ && priority > settings_.priority);
}

bool RoleMachine::peer_dds_fresh(Time now) const noexcept { return dds_seen_ && now - *dds_seen_ < settings_.lease; }

// Lost, not merely unheard: we have listened for a whole lease and heard nothing within it.
bool RoleMachine::peer_dds_absent(Time now) const noexcept {
  return !peer_dds_fresh(now) && now - listening_since_ >= settings_.lease;
}

bool RoleMachine::peer_can_recent(Time now) const noexcept {
  return can_seen_ && can_last_.claim != CanClaim::Released && now - *can_seen_ < settings_.can_silence;
}

// Silence counts only after listening for can_silence; the peer's release is its promise of it.
bool RoleMachine::peer_can_quiet(Time now) const noexcept {
  if (peer_can_recent(now)) return false;
  if (can_seen_ && can_last_.claim == CanClaim::Released) return true;
  return now - listening_since_ >= settings_.can_silence;
}

// For an instance that neither owns nor claims the bus: does the peer's DDS heartbeat keep it
// from claiming? An unheard peer (less than a lease of listening) does.
bool RoleMachine::peer_holds_on_dds(Time now) const noexcept {
  if (!peer_dds_fresh(now)) return !peer_dds_absent(now);
  switch (dds_last_.role) {
    case Role::Active:
    case Role::Claiming: return true;
    case Role::NoBus:
    case Role::Leaving: return false;
    case Role::Joining:
    case Role::Standby:
    case Role::Fenced: break;
  }
  if (dds_last_.hands_over) return false;
  if (deferring_) return true;
  return settings_.priority <= dds_last_.priority;
}

bool RoleMachine::peer_claims_stronger(Time now) const noexcept {
  if (peer_dds_fresh(now) && (dds_last_.role == Role::Active || dds_last_.role == Role::Claiming) &&
      stronger(dds_last_.term, dds_last_.priority))
    return true;
  return peer_can_recent(now) && stronger(can_last_.term, can_last_.priority);
}

Role RoleMachine::passive_role(Time now) const noexcept {
  if (peer_dds_fresh(now)) return Role::Standby;
  if (peer_dds_absent(now)) return peer_can_recent(now) ? Role::Fenced : Role::Standby;
  return role_ == Role::Joining ? Role::Joining : Role::Standby;
}

PeerAlarm RoleMachine::judge_alarm(Time now) const noexcept {
  if (role_ == Role::Leaving) return PeerAlarm::None;
  if ((peer_dds_fresh(now) && dds_last_.priority == settings_.priority) ||
      (peer_can_recent(now) && can_last_.priority == settings_.priority))
    return PeerAlarm::PriorityClash;
  if (peer_dds_absent(now)) return peer_can_recent(now) ? PeerAlarm::Partition : PeerAlarm::PeerUnreachable;
  return PeerAlarm::None;
}

void RoleMachine::step(Time now) {
  if (role_ == Role::Leaving) {
    alarm_ = PeerAlarm::None;
    return;
  }
  if (bus_ != BusState::Ok) {
    set_role(Role::NoBus);
  } else {
    if (role_ == Role::NoBus) {
      // Nothing was heard while the bus was away: its silence then says nothing.
      can_seen_.reset();
      start_listening(now);
      set_role(Role::Joining);
    }
    switch (role_) {
      case Role::Active:
        if (peer_claims_stronger(now)) set_role(passive_role(now));
        break;
      case Role::Claiming:
        if (peer_claims_stronger(now))
          set_role(passive_role(now));
        else if (now - claim_start_ >= claim_window(settings_) && peer_can_quiet(now))
          set_role(Role::Active);
        break;
      case Role::Joining:
      case Role::Standby:
      case Role::Fenced:
        if (peer_can_quiet(now) && !peer_holds_on_dds(now)) {
          term_ = max_term_ + 1;
          max_term_ = term_;
          claim_start_ = now;
          set_role(Role::Claiming);
        } else {
          set_role(passive_role(now));
        }
        break;
      case Role::NoBus:
      case Role::Leaving: break;
    }
  }
  const PeerAlarm alarm = judge_alarm(now);
  if (alarm != alarm_) changed_ = true;
  alarm_ = alarm;
}

void RoleMachine::on_peer_heartbeat(Time now, const DdsBeat& beat) {
  enter(now);
  if (role_ == Role::Leaving) return;
  dds_seen_ = now;
  dds_last_ = beat;
  max_term_ = std::max(max_term_, beat.term);
  if (beat.role == Role::Active || beat.role == Role::Claiming) deferring_ = false;
  step(now);
}

void RoleMachine::on_peer_can(Time now, const CanBeat& beat) {
  enter(now);
  if (role_ == Role::Leaving) return;
  can_seen_ = now;
  can_last_ = beat;
  max_term_ = std::max(max_term_, beat.term);
  if (beat.claim != CanClaim::Released) {
    deferring_ = false;
    // A weaker claimant yields on hearing us: tell it now, not a period later.
    if ((role_ == Role::Active || role_ == Role::Claiming) && !stronger(beat.term, beat.priority)) answer_claim_ = true;
  }
  step(now);
}

void RoleMachine::on_bus_state(Time now, BusState state) {
  enter(now);
  bus_ = state;
  step(now);
}

void RoleMachine::leave(Time now) {
  enter(now);
  // A claimant has been heard on the bus too: its release lets the peer take over at once.
  if ((role_ == Role::Active || role_ == Role::Claiming) && bus_ == BusState::Ok) release_pending_ = true;
  deferring_ = false;
  set_role(Role::Leaving);
  alarm_ = PeerAlarm::None;
}

MoveResult RoleMachine::hand_over(Time now) {
  enter(now);
  step(now);
  if (role_ != Role::Active)
    return {false, "this instance is " + std::string(role_name(role_)) + ", not active: only the bus owner hands over"};
  if (!peer_dds_fresh(now))
    return {false, "the peer's role heartbeat is older than the lease: nobody could take the bus"};
  if (dds_last_.role != Role::Standby)
    return {false, "the peer is " + std::string(role_name(dds_last_.role)) + ", not standby: it cannot take the bus"};
  deferring_ = true;
  release_pending_ = true;
  set_role(Role::Standby);
  return {true, {}};
}

Actions RoleMachine::poll(Time now) {
  enter(now);
  step(now);
  Actions a;
  if (changed_ || !dds_sent_ || now - *dds_sent_ >= settings_.heartbeat_period) {
    a.dds = DdsBeat{role_, term_, settings_.priority, deferring_};
    dds_sent_ = now;
    changed_ = false;
  }
  if (release_pending_) {
    a.can = CanBeat{CanClaim::Released, settings_.priority, term_};
    release_pending_ = false;
    can_sent_ = now;
    can_claim_sent_ = CanClaim::Released;
  } else if (role_ == Role::Active || role_ == Role::Claiming) {
    const CanClaim claim = role_ == Role::Active ? CanClaim::Active : CanClaim::Claiming;
    if (answer_claim_ || can_claim_sent_ != claim || !can_sent_ ||
        now - *can_sent_ >= can_heartbeat_period(settings_)) {
      a.can = CanBeat{claim, settings_.priority, term_};
      can_sent_ = now;
      can_claim_sent_ = claim;
      answer_claim_ = false;
    }
  }
  return a;
}

}  // namespace pmu::redundancy
