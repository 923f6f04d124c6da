// Time passing: power-up/reset, energy integration, cranking, thermal shutdown, streaming.

#include <algorithm>
#include <chrono>
#include <utility>

#include "model_state.hpp"

namespace pmu::sim::detail {
namespace {

using codec::Parameter;

}  // namespace

ModelState::ModelState(const DeviceConfig& config, FrameSink sink, TimePoint now)
    : firmware(config.firmware),
      serial_number(config.serial_number),
      build_date(config.build_date),
      params(config.parameters),
      address(config.address),
      outbox(std::move(sink)),
      last(now) {
  params.set_raw(Parameter::CanAddress, config.address);
  restart(now);
}

void ModelState::restart(TimePoint now) noexcept {
  // 5.24: outputs to their power-up states, battery energies to zero, generation on.
  outputs = static_cast<std::uint8_t>(params.raw(Parameter::PowerUpState) & codec::output_bit::All);
  mah_a = mah_b = 0;
  generation_on = true;
  // Chosen: a restarting unit lets go of the starter; a running engine keeps running.
  if (engine == EngineState::Cranking) engine = EngineState::Stopped;
  // The restarted unit decides thermal shutdown afresh (no memory of the hysteresis band).
  thermal = false;
  update_thermal();
  next_stream = now + packet_period();
}

void ModelState::integrate(TimePoint to) noexcept {
  if (to <= last) return;
  const double seconds = std::chrono::duration<double>(to - last).count();
  const codec::Currents c = currents(plant, operating());
  // Table 4: the time-integral of current into the battery, in mAh (1 A for 3.6 s = 1 mAh).
  mah_a += c.battery_a * seconds / 3.6;
  mah_b += c.battery_b * seconds / 3.6;
  last = to;
}

void ModelState::advance(TimePoint now) noexcept {
  // Cranking may end inside the interval; integrate each side of that instant with the
  // currents that applied, so the result does not depend on how often tick() is called.
  for (;;) {
    if (engine == EngineState::Cranking) {
      const auto end = crank_outcome(crank_since, plant.engine_starts_after, cranking_time());
      if (end && end->at <= now) {
        integrate(std::max(end->at, last));
        engine = end->result;
        continue;
      }
    }
    integrate(now);
    break;
  }
  update_thermal();
}

void ModelState::update_thermal() noexcept {
  thermal = next_thermal_shutdown(thermal, plant.internal_temperature, params.raw(Parameter::UpperTemperatureLimit));
}

void ModelState::tick(TimePoint now) noexcept {
  const Outbox::Batch batch(outbox);
  now = clamp_time(now);
  advance(now);
  outbox.release(now);  // older held frames first; the outbox keeps FIFO order anyway
  if (now >= next_stream) {
    const auto groups = static_cast<std::uint8_t>(params.raw(Parameter::PacketsStreamed) & codec::group_bit::All);
    if (groups != 0) send_telemetry(groups, now);
    // Drift-free while ticks keep up; after a stall (or silence) resume without a burst.
    next_stream += packet_period();
    if (next_stream <= now) next_stream = now + packet_period();
  }
}

TimePoint ModelState::next_deadline() const noexcept {
  TimePoint t = next_stream;
  if (engine == EngineState::Cranking) {
    if (const auto end = crank_outcome(crank_since, plant.engine_starts_after, cranking_time()))
      t = std::min(t, end->at);
  }
  if (const auto held = outbox.next_release()) t = std::min(t, *held);
  return std::max(t, last);
}

Duration ModelState::packet_period() const noexcept {
  // Table 12: PP in 0.1 s. A preloaded 0 (no set can write it) would stream on every tick;
  // treat it as the shortest period instead.
  const auto pp = std::max<std::uint32_t>(params.raw(Parameter::PacketPeriod), 1);
  return codec::duration_of(Parameter::PacketPeriod, pp);
}

Duration ModelState::cranking_time() const noexcept {
  // Table 17: CT in 0.1 s; 0 disables the timeout (Duration::zero() means none).
  return codec::duration_of(Parameter::CrankingTime, params.raw(Parameter::CrankingTime));
}

Operating ModelState::operating() const noexcept {
  Operating op;
  op.outputs = outputs;
  op.generation_on = generation_on;
  op.thermal_shutdown = thermal;
  op.engine = engine;
  op.avionics_setpoint = codec::parameter_value(Parameter::AvionicsVoltage, params.raw(Parameter::AvionicsVoltage));
  op.payload_setpoint = codec::parameter_value(Parameter::PayloadVoltage, params.raw(Parameter::PayloadVoltage));
  op.servo_setpoint = codec::parameter_value(Parameter::ServoVoltage, params.raw(Parameter::ServoVoltage));
  return op;
}

Telemetry ModelState::telemetry() const noexcept {
  using codec::Feature;
  const Operating op = operating();
  Telemetry t;
  t.voltages = clamped(voltages(plant, op));
  t.currents = clamped(currents(plant, op));
  t.energy = energy_field(mah_a, mah_b);

  codec::Temperatures temps;
  temps.internal = plant.internal_temperature;
  temps.starter = plant.starter_temperature;
  // Before 1.12 there was no external sensing (v1.9 6.1): report "no sensor".
  if (codec::supports(firmware, Feature::ExternalTemperatures)) {
    temps.battery_a = plant.battery_a_temperature;
    temps.battery_b = plant.battery_b_temperature;
    temps.generator = plant.generator_temperature;
  }
  t.temperatures = clamped(temps);

  codec::Status& s = t.status;
  s.generator_rpm = generator_rpm(plant, op);
  s.generation_enabled = generation_on;
  s.thermal_shutdown = thermal;
  // Flag register 0 bit 6 carries one meaning per firmware (v1.9 6.8); the other reads false.
  s.interpretation = codec::interpret_flags(firmware);
  const bool soa_bit = s.interpretation.bit6 == codec::Bit6Meaning::SoaShutdown;
  s.soa_shutdown = soa_bit && plant.soa_shutdown;
  s.start_button = !soa_bit && plant.start_button;
  s.payload_shed = plant.payload_shed;
  s.starter_ready = codec::supports(firmware, Feature::StarterReadyFlag) && plant.starter_ready;
  s.outputs = outputs;
  return t;
}

void ModelState::send_telemetry(std::uint8_t groups, TimePoint now) noexcept {
  namespace gb = codec::group_bit;
  // One snapshot for the whole burst, in packet id order (table 7 bit order).
  const Telemetry t = telemetry();
  const auto one = [&](codec::Encoded e) {
    if (e && outbox.faults().telemetry_length) {
      // Wrong-length fault: same bytes, wrong data length code (extra bytes are zero).
      e.value().length = std::min(*outbox.faults().telemetry_length, codec::kMaxDataLength);
    }
    send(e, now);
  };
  if (groups & gb::Voltages) one(codec::encode_voltages(t.voltages, address));
  if (groups & gb::Currents) one(codec::encode_currents(t.currents, address));
  if (groups & gb::BatteryEnergy) one(codec::encode_battery_energy(t.energy, address));
  if (groups & gb::Temperatures) one(codec::encode_temperatures(t.temperatures, address));
  if (groups & gb::Status) one(codec::encode_status(t.status, address, firmware));
}

void ModelState::send(const codec::Encoded& frame, TimePoint now) noexcept {
  if (!frame) {
    ++counters.encode_errors;
    return;
  }
  outbox.send(*frame, now);
}

}  // namespace pmu::sim::detail
