#pragma once
// ReadingMachine: what the service knows of one device's identity and stored state, and
// the rounds of gets that learn it.
//
//   READING  a round of gets is out: serial, firmware, every stored parameter, outputs,
//            generation (packets(), in that order). Done when every one was answered;
//            the first that is not (the device is silent) fails the round, and a new one
//            is due `retry_delay` later (or at the device's next frame).
//   RUNNING  everything was read; the session publishes info and config and serves.
// start() begins a new round from either phase (after OFFLINE, after a reset); answers
// to an earlier round are ignored from then on.
//
// Every decoded frame is absorbed, whatever the phase: answers, and the status packet
// that streams the outputs and generation states too, keep the stored values current.
// absorb() says what changed; the caller publishes it once RUNNING.
//
// No I/O, no clock: the caller sends the gets and brings the time.

#include <chrono>
#include <cstdint>
#include <optional>
#include <vector>

#include "pmu/codec/decode.hpp"
#include "pmu/session/device_state.hpp"

namespace pmu::service {

class ReadingMachine {
 public:
  // The gets of one round, in the order they are sent.
  static const std::vector<codec::PacketId>& packets();

  // Begins a new round; returns its number, which on_result() wants back.
  std::uint64_t start() noexcept;

  enum class Progress : std::uint8_t {
    Ignored,  // an answer to an earlier or already failed round
    Pending,  // more gets of the round are outstanding
    Done,     // the round is complete: now RUNNING
    Failed,   // the round is over: drop its remaining gets, retry once retry_due()
  };
  Progress on_result(std::uint64_t round, bool answered, std::chrono::steady_clock::time_point now,
                     std::chrono::milliseconds retry_delay) noexcept;

  bool running() const noexcept { return phase_ == Phase::Running; }
  // The last round failed and no new one has started.
  bool failed() const noexcept { return failed_; }
  bool retry_due(std::chrono::steady_clock::time_point now) const noexcept { return failed_ && now >= retry_at_; }

  struct Changes {
    bool info = false;
    bool config = false;
  };
  Changes absorb(const codec::PmuMessage& m);

  // Every packet of a round has been heard answered since the last forget_heard(), to
  // whoever asked: a standby of a hot-standby pair, whose own gets never go out, knows the
  // device from its peer's reading (docs/design.md, "Hot standby").
  bool heard_all() const noexcept { return heard_ == all_heard(); }
  void forget_heard() noexcept { heard_ = 0; }
  // The round ends as if answered: RUNNING, from what was heard.
  void complete_from_heard() noexcept {
    phase_ = Phase::Running;
    failed_ = false;
  }

  // The unit answers at `address` now (a verified or observed CAN address change): its
  // stored CA is that, whatever was last read.
  void set_address(std::uint16_t address) noexcept {
    config_.raw[static_cast<std::size_t>(codec::Parameter::CanAddress)] = address;
  }

  const ConfigState& config() const noexcept { return config_; }
  const std::optional<InfoState>& info() const noexcept { return info_; }
  // Known once the firmware packet was read; until then decoding assumes nothing.
  std::optional<codec::FirmwareVersion> firmware() const noexcept;

 private:
  enum class Phase : std::uint8_t { Reading, Running };

  Phase phase_ = Phase::Reading;
  std::uint64_t round_ = 0;
  unsigned left_ = 0;  // gets of the current round still to be answered
  bool failed_ = false;
  std::chrono::steady_clock::time_point retry_at_{};
  ConfigState config_;
  std::optional<InfoState> info_;
  std::uint32_t heard_ = 0;  // bit i: packets()[i] heard answered
  static std::uint32_t all_heard() noexcept;
};

}  // namespace pmu::service
