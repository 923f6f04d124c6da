#pragma once
// BatteryModel: the BMS of a solar-boat MG battery as seen on the CAN bus
// (spec/solar-boat-canopen-battery-mppt.txt, "Battery (MG) CAN-format").
//
// Every value of the battery's table goes out once per period, one frame at a time spread
// evenly over it, in the table's order: 0x302 voltage, currents, state of charge, time to go;
// 0x402 cell temperatures high/low, cell voltages high/low, BMS state, temperature
// collection; 0x482 each cell's voltage (subindex = cell number, 1..cells); 0x202 power
// level. The values are those of the SolarPlant at the moment each frame is sent, clamped
// into what the field carries, and built by codec::canopen's encoders.
//
// Like PmuModel it reads no clock, starts no thread and does no I/O: tick(now) sends what is
// due, next_deadline() says when. It listens to nothing (the document gives it no requests).
//
//   auto plant = std::make_shared<SolarPlant>(SolarWorld{}, now);
//   BatteryModel bms(BatterySimConfig{}, plant, [&](const codec::CanFrame& f) { bus.send(f); }, now);
//   every few ms: bms.tick(clock.now());

#include <cstddef>
#include <cstdint>
#include <memory>

#include "pmu/sim/config.hpp"
#include "pmu/sim/pmu_model.hpp"
#include "pmu/sim/solar_config.hpp"
#include "pmu/sim/solar_plant.hpp"

namespace pmu::sim {

class BatteryModel {
 public:
  // Joins `plant` (nullptr: a plant of its own with SolarWorld's defaults, no MPPT: the load
  // alone). The first frame is due at `now`. Throws std::invalid_argument at start-up for a
  // node outside 1..127, cells outside 1..15, a period <= 0, a capacity <= 0 or an initial
  // state of charge outside 0..1.
  BatteryModel(const BatterySimConfig& config, std::shared_ptr<SolarPlant> plant, FrameSink sink, TimePoint now);
  ~BatteryModel();  // leaves the plant
  BatteryModel(const BatteryModel&) = delete;
  BatteryModel& operator=(const BatteryModel&) = delete;

  void tick(TimePoint now) noexcept;
  TimePoint next_deadline() const noexcept;

  void set_faults(const CanOpenFaults& faults) noexcept;
  const CanOpenFaults& faults() const noexcept;

  std::uint8_t node() const noexcept { return config_.node; }
  const BatterySimConfig& config() const noexcept { return config_; }
  std::size_t frames_per_period() const noexcept;  // 13 values + one per cell
  SolarPlant& plant() noexcept { return *plant_; }
  const SolarPlant& plant() const noexcept { return *plant_; }
  BatteryReading reading() const noexcept;  // unclamped, at the plant's last advance
  CanOpenCounters counters() const noexcept;

 private:
  void send_frame(std::size_t slot) noexcept;

  BatterySimConfig config_;
  std::shared_ptr<SolarPlant> plant_;
  struct Sender;
  std::unique_ptr<Sender> sender_;
  TimePoint last_;
  std::uint64_t token_ = 0;  // our entry in the plant
};

}  // namespace pmu::sim
