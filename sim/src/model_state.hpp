#pragma once
// The state behind PmuModel and the rules that change it. Split in two sources:
// model_time.cpp (power-up, time passing, telemetry) and model_frames.cpp (what each
// received packet does).

#include <cstdint>

#include "outbox.hpp"
#include "physics.hpp"
#include "pmu/codec/decode.hpp"
#include "pmu/codec/encode.hpp"
#include "pmu/sim/config.hpp"
#include "pmu/sim/pmu_model.hpp"

namespace pmu::sim::detail {

struct ModelState {
  ModelState(const DeviceConfig& config, FrameSink sink, TimePoint now);

  // ---- fixed identity ----
  codec::FirmwareVersion firmware;
  std::uint16_t serial_number;
  BuildDate build_date;

  // ---- stored (non-volatile) ----
  StoredParameters params;
  std::uint16_t address;  // follows CA at once (see model_frames.cpp)

  // ---- volatile ----
  Plant plant{};
  Outbox outbox;
  std::uint8_t outputs = 0;
  bool generation_on = true;
  bool thermal = false;
  EngineState engine = EngineState::Stopped;
  TimePoint crank_since{};
  double mah_a = 0, mah_b = 0;
  TimePoint last{};         // the time the state has been advanced to
  TimePoint next_stream{};  // when the next streamed burst is due
  Counters counters{};

  // model_time.cpp
  TimePoint clamp_time(TimePoint now) const noexcept { return now < last ? last : now; }
  void restart(TimePoint now) noexcept;
  void advance(TimePoint now) noexcept;
  void update_thermal() noexcept;
  void tick(TimePoint now) noexcept;
  TimePoint next_deadline() const noexcept;
  Duration packet_period() const noexcept;
  Duration cranking_time() const noexcept;
  Operating operating() const noexcept;
  Telemetry telemetry() const noexcept;
  void send_telemetry(std::uint8_t groups, TimePoint now) noexcept;
  void send(const codec::Encoded& frame, TimePoint now) noexcept;

  // model_frames.cpp
  void on_frame(const codec::CanFrame& frame, TimePoint now) noexcept;
  void handle(const codec::PmuMessage& msg, TimePoint now) noexcept;
  void handle_parameter(const codec::PmuMessage& msg, TimePoint now) noexcept;
  bool addressed_to_us(std::uint16_t to) const noexcept { return to == address || to == codec::kBroadcastAddress; }

 private:
  void integrate(TimePoint to) noexcept;
};

}  // namespace pmu::sim::detail
