#pragma once
// MpptModel: a solar-boat MPPT as seen on the CAN bus
// (spec/solar-boat-canopen-battery-mppt.txt, "MPPT CAN-format"; device 0..7, COB-ID
// 0x4E6 + 8 * device, the third table on base + 1 as codec/canopen.hpp reads it).
//
// Every value of the MPPT's tables goes out once per period, one frame at a time spread evenly
// over it: output voltage/current, OUT_SW voltage, state, safety, PWM, temperature, the four
// panels' voltage and current, then (base + 1) the four duty cycles and the channel map.
// Voltages and currents are counts of kMpptVoltsPerCount / kMpptAmpsPerCount (solar_plant.hpp):
// the document gives them no resolution. Values come from the SolarPlant at send time.
// Same shape as BatteryModel: tick(now), next_deadline(), no clock, no I/O.

#include <cstddef>
#include <cstdint>
#include <memory>

#include "pmu/sim/config.hpp"
#include "pmu/sim/pmu_model.hpp"
#include "pmu/sim/solar_config.hpp"
#include "pmu/sim/solar_plant.hpp"

namespace pmu::sim {

class MpptModel {
 public:
  // Joins `plant` (nullptr: a plant of its own, no battery). First frame due at `now`.
  // Throws std::invalid_argument at start-up for a device above 7, panels outside 0..4, a
  // period <= 0 or a negative panel rating.
  MpptModel(const MpptSimConfig& config, std::shared_ptr<SolarPlant> plant, FrameSink sink, TimePoint now);
  ~MpptModel();  // leaves the plant
  MpptModel(const MpptModel&) = delete;
  MpptModel& operator=(const MpptModel&) = delete;

  void tick(TimePoint now) noexcept;
  TimePoint next_deadline() const noexcept;

  void set_faults(const CanOpenFaults& faults) noexcept;
  const CanOpenFaults& faults() const noexcept;

  std::uint8_t device() const noexcept { return config_.device; }
  const MpptSimConfig& config() const noexcept { return config_; }
  static constexpr std::size_t frames_per_period() noexcept { return 20; }
  SolarPlant& plant() noexcept { return *plant_; }
  const SolarPlant& plant() const noexcept { return *plant_; }
  MpptReading reading() const noexcept;  // unclamped, at the plant's last advance
  CanOpenCounters counters() const noexcept;

 private:
  void send_frame(std::size_t slot) noexcept;

  MpptSimConfig config_;
  std::shared_ptr<SolarPlant> plant_;
  struct Sender;
  std::unique_ptr<Sender> sender_;
  TimePoint last_;
  std::uint64_t token_ = 0;  // our entry in the plant
};

}  // namespace pmu::sim
