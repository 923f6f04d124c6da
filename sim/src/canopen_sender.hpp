#pragma once
// What the battery and MPPT models share: the schedule that spreads a device's values over
// its period, and the transmit path with the silence and garble faults.

#include <cstddef>
#include <cstdint>
#include <optional>

#include "pmu/codec/encode.hpp"
#include "pmu/sim/config.hpp"
#include "pmu/sim/pmu_model.hpp"
#include "pmu/sim/solar_config.hpp"

namespace pmu::sim::detail {

// `count` frames per `period`, frame k due at start + k * period / count: a BMS sends its
// values one at a time, not in a burst.
class Spread {
 public:
  Spread(Duration period, std::size_t count, TimePoint start) noexcept;
  TimePoint next() const noexcept;
  // Calls send(k) for each frame due by `now`, in order. After a stall of a period or more
  // (a harness that stopped ticking) it restarts at frame 0 now instead of bursting.
  template <class Send>
  void due(TimePoint now, Send&& send) {
    if (now - next() >= period_) {
      start_ = now;
      slot_ = 0;
    }
    while (next() <= now) {
      send(slot_);
      if (++slot_ == count_) {
        slot_ = 0;
        start_ += period_;
      }
    }
  }

 private:
  Duration period_;
  std::size_t count_;
  TimePoint start_;
  std::size_t slot_ = 0;
};

// How the UnknownSubindex garble spoils one frame: a subindex the document leaves blank for
// this id, else an index it does not have, else (0x202, which checks neither) a short frame.
struct Spoil {
  std::optional<std::uint8_t> blank_subindex;
  std::optional<std::uint16_t> unknown_index;
};

class CanOpenSender {
 public:
  explicit CanOpenSender(FrameSink sink) noexcept;
  void set_faults(const CanOpenFaults& faults) noexcept { faults_ = faults; }
  const CanOpenFaults& faults() const noexcept { return faults_; }
  const CanOpenCounters& counters() const noexcept { return counters_; }
  void send(const codec::Encoded& frame, const Spoil& spoil) noexcept;

 private:
  FrameSink sink_;
  CanOpenFaults faults_{};
  CanOpenCounters counters_{};
};

}  // namespace pmu::sim::detail
