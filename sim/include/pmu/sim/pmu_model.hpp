#pragma once
// PmuModel: a transport-independent model of one Millswood 250W PMU on a CAN bus.
//
// The platform hands it every frame seen on the bus (on_frame) and calls tick() regularly;
// the model answers and streams through the FrameSink it was given. It reads no clock
// (every call carries `now`), starts no thread and does no I/O, so tests drive it with a
// fake time_point and a later step binds it to a CanBus. Like the codec, it never throws
// on the frame path: a frame it cannot use is counted (Counters) and otherwise ignored.
//
//   PmuModel pmu(DeviceConfig{}, [&](const codec::CanFrame& f) { bus.send(f); }, now);
//   bus.on_receive([&](const codec::CanFrame& f) { pmu.on_frame(f, clock.now()); });
//   every few ms: pmu.tick(clock.now());   // or sleep until pmu.next_deadline()
//
// Every frame is parsed with codec::decode and built with the codec's device-side
// encoders; this file knows no byte layout.
//
// Bus assumption: the model must not be handed its own frames back (SocketCAN's default,
// CAN_RAW_RECV_OWN_MSGS off). The protocol answers a get with the same packet id a set
// uses, so an echoed reply would be taken for a set of the same value.

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>

#include "pmu/codec/can_frame.hpp"
#include "pmu/codec/messages.hpp"
#include "pmu/sim/config.hpp"

namespace pmu::sim {

// Called synchronously for every frame the unit puts on the bus; it must not throw. It may
// call back into the model (an in-process bus delivering a request at once): what that call
// makes the unit send is queued behind everything already being sent, so a burst (a 0x0F
// answer, a streamed period) is never split.
using FrameSink = std::function<void(const codec::CanFrame&)>;

enum class EngineState : std::uint8_t {
  Stopped,
  Cranking,  // starter engaged (0x24) until the engine fires, CT elapses or 0x25
  Running,
};

// What happened to the frames the model saw and sent. Every frame given to on_frame lands
// in exactly one of the "in" buckets after frames_in.
struct Counters {
  std::uint64_t frames_in = 0;
  std::uint64_t handled = 0;           // a get answered, a set stored, a command carried out
  std::uint64_t not_pmu = 0;           // 11-bit id, or a group other than 0x1E
  std::uint64_t other_address = 0;     // a PMU frame for another unit
  std::uint64_t unknown_packet = 0;    // to us, packet id not in table 1
  std::uint64_t wrong_length = 0;      // to us, data length not allowed for the packet
  std::uint64_t malformed = 0;         // to us, remote frame or length code above 8
  std::uint64_t rejected_sets = 0;     // out of range / undefined bits: stored value kept
  std::uint64_t ignored_sets = 0;      // valid, but Faults::ignored_set: stored value kept
  std::uint64_t unsupported = 0;       // packet this firmware lacks (0x0F before 1.14)
  std::uint64_t not_commands = 0;      // data-carrying telemetry or replies (another unit's)
  std::uint64_t ignored_commands = 0;  // 0x24 while cranking/running or starter not ready
  std::uint64_t ignored_silent = 0;    // to us while the silence fault is on

  std::uint64_t frames_out = 0;     // handed to the sink
  std::uint64_t lost = 0;           // dropped by the loss fault
  std::uint64_t suppressed = 0;     // not sent because of the silence fault
  std::uint64_t encode_errors = 0;  // a NaN where the field has no "no sensor" value
};

// The values the next telemetry frames would carry: SI units, already clamped into each
// field's range (tables 2..6).
struct Telemetry {
  codec::Voltages voltages;
  codec::Currents currents;
  codec::BatteryEnergy energy;
  codec::Temperatures temperatures;
  codec::Status status;
};

class PmuModel {
 public:
  // `now` is the power-up time: streaming starts one packet period later and energies
  // integrate from here. Throws std::invalid_argument for a broadcast address (start-up
  // configuration is the only place this class throws).
  PmuModel(const DeviceConfig& config, FrameSink sink, TimePoint now);
  ~PmuModel();
  PmuModel(const PmuModel&) = delete;
  PmuModel& operator=(const PmuModel&) = delete;
  PmuModel(PmuModel&&) noexcept;
  PmuModel& operator=(PmuModel&&) noexcept;

  // A frame seen on the bus at `now`. Acted on when addressed to address() or 0xFFFF.
  void on_frame(const codec::CanFrame& frame, TimePoint now) noexcept;
  // Advance to `now`: integrate energies, finish cranking, update thermal shutdown, stream
  // when a packet period has passed, release delayed frames. Times earlier than the last
  // one seen are treated as the last one (a steady clock never goes back).
  void tick(TimePoint now) noexcept;
  // The earliest time at which tick() has something to do (stream, cranking outcome,
  // delayed frame); a binding may sleep until then.
  TimePoint next_deadline() const noexcept;

  // ---- harness controls (the world outside the CAN protocol) ----
  // The new plant applies from `now`; energy up to `now` is integrated with the old one.
  void set_plant(const Plant& plant, TimePoint now) noexcept;
  const Plant& plant() const noexcept;
  void set_faults(const Faults& faults) noexcept;
  const Faults& faults() const noexcept;
  // The engine started or stalled by itself (or was running before the PMU powered up).
  void set_engine_running(bool running, TimePoint now) noexcept;
  // Power-cycle: like 0x26 Reset (the stored parameters survive, being non-volatile).
  void power_cycle(TimePoint now) noexcept;

  // ---- observation ----
  std::uint16_t address() const noexcept;
  codec::FirmwareVersion firmware() const noexcept;
  std::uint32_t parameter(codec::Parameter p) const noexcept;  // stored raw value
  std::uint8_t outputs() const noexcept;                       // output_bit::*
  bool generation_enabled() const noexcept;
  bool thermal_shutdown() const noexcept;
  EngineState engine_state() const noexcept;
  double battery_a_mah() const noexcept;  // unrounded integrals
  double battery_b_mah() const noexcept;
  Telemetry telemetry() const noexcept;
  Counters counters() const noexcept;
  std::size_t frames_held() const noexcept;  // waiting in the delay fault's queue

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace pmu::sim
