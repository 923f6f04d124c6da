#pragma once
// RoleHolder: one instance of a hot-standby pair at run time (docs/design.md, "Hot standby").
// It holds the pure role machine (pmu/redundancy/role_machine.hpp), feeds it what the bus and
// the peer's role heartbeats say, sends the CAN heartbeat the machine asks for on the bus, and
// hands the DDS heartbeat and every change of role to the program.
//
// Threads. The machine has no lock of its own: every call here takes the holder's mutex.
// The bus's thread (the BusWorker's) calls tick(), may_transmit(), on_can_frame() and
// on_bus_state(); those ask the machine what to do now and do it: the CAN heartbeat goes out
// on that thread (one thread uses a bus at a time), and `Outputs::changed` is called on it, so
// every change of role is seen in order on one thread. Any thread may call on_report(),
// leave(), hand_over(), role() and status(): they only tell the machine, and what
// follows is done at the bus thread's next call (at most the tick period later).
//
// Lifetime: the bus given to attach() must outlive the holder's last call from the bus
// thread (FencedBus owns it and attaches it). The functions in Outputs are called with no
// lock of the holder held, and must not call back into it.

#include <chrono>
#include <cstdint>
#include <functional>
#include <mutex>
#include <optional>
#include <string>

#include "pmu/codec/can_frame.hpp"
#include "pmu/redundancy/role.hpp"
#include "pmu/redundancy/role_machine.hpp"
#include "pmu/redundancy/settings.hpp"
#include "pmu/transport/can_bus.hpp"

namespace pmu::standby {

using Time = std::chrono::steady_clock::time_point;

struct RoleChange {
  redundancy::Role from = redundancy::Role::Joining;
  redundancy::Role to = redundancy::Role::Joining;
  std::uint32_t term = 0;
  redundancy::PeerAlarm alarm = redundancy::PeerAlarm::None;
  // What the gates follow: the bus taken or given up. A change of alarm alone is neither.
  bool took_bus() const noexcept { return to == redundancy::Role::Active && from != redundancy::Role::Active; }
  bool left_bus() const noexcept { return from == redundancy::Role::Active && to != redundancy::Role::Active; }
};

class RoleHolder {
 public:
  struct Outputs {
    std::function<void(const redundancy::RoleReport&)> publish;  // pmu/role, when the machine says it is due
    std::function<void(const RoleChange&)> changed;              // after a change of role or alarm
    // While this instance owns the bus, its peer was heard on DDS after a lease or more of
    // silence (it started, or came back): the devices' stored values are to be asked again, so
    // that the peer, which cannot ask, hears them answered.
    std::function<void()> peer_joined;
  };

  // `settings.name` must be set (the config fills it with the host's name when absent).
  RoleHolder(redundancy::Settings settings, Time now, Outputs outputs);
  RoleHolder(const RoleHolder&) = delete;
  RoleHolder& operator=(const RoleHolder&) = delete;

  // --- the bus's thread ---
  void attach(transport::CanBus& bus, Time now);
  // The machine's poll: its heartbeats sent, its changes handed on. At least every
  // redundancy::poll_period(settings).
  void tick(Time now);
  // Whether a PMU frame may go on the bus now: asked right before each one, after telling the
  // machine the time, so that a holder frozen while ACTIVE stops on its first frame.
  bool may_transmit(Time now);
  // A frame on a heartbeat identifier (redundancy::is_can_beat_id): the peer's. Anything that
  // does not decode as a heartbeat is dropped.
  void on_can_frame(Time now, const codec::CanFrame& frame);
  void on_bus_state(Time now, transport::BusState state);

  // --- any thread ---
  // A pmu/role sample with its arrival time; only the configured peer's are the machine's.
  void on_report(const redundancy::RoleReport& report, Time arrival);
  // SIGTERM: the machine stops transmitting at once; the release goes out at the next tick.
  void leave(Time now);
  // A move of the role (pmuctl): accepted or refused with the reason. The move's endpoint
  // audits it.
  redundancy::MoveResult hand_over(Time now);
  redundancy::Role role() const;
  // The machine's owns_at(now): ACTIVE and judged by the bus's thread within freeze_gap.
  bool owns_bus(Time now) const;
  // "ACTIVE, term 3" or "STANDBY (peer mc-b ACTIVE)": systemd's STATUS= and the log.
  std::string status() const;
  const redundancy::Settings& settings() const noexcept { return settings_; }

 private:
  struct Due {
    std::optional<redundancy::RoleReport> report;
    std::optional<redundancy::CanBeat> can;
    std::optional<RoleChange> change;
    bool peer_joined = false;
  };
  Due collect(Time now);  // with mutex_ held
  void act(const Due& due);

  const redundancy::Settings settings_;
  Outputs outputs_;
  mutable std::mutex mutex_;
  redundancy::RoleMachine machine_;
  redundancy::Role reported_role_ = redundancy::Role::Joining;
  redundancy::PeerAlarm reported_alarm_ = redundancy::PeerAlarm::None;
  redundancy::BusState bus_state_ = redundancy::BusState::Ok;
  std::optional<redundancy::RoleReport> peer_;
  Time peer_seen_{};
  bool peer_joined_ = false;          // the peer heard after a lease of silence, not yet handed on
  transport::CanBus* bus_ = nullptr;  // bus thread only
};

// The machine's view of a bus state: warning and passive still carry frames.
redundancy::BusState machine_bus_state(transport::BusState state) noexcept;

}  // namespace pmu::standby
