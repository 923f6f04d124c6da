// What each received packet does (v1.9 section 5). Parsing is codec::decode's; this file
// only applies the decoded message to the state and answers through the codec's encoders.

#include <utility>
#include <variant>

#include "model_state.hpp"

namespace pmu::sim::detail {
namespace {

using codec::PacketId;

template <class T>
const T* payload(const codec::PmuMessage& msg) noexcept {
  return std::get_if<T>(&msg.payload);
}

}  // namespace

void ModelState::on_frame(const codec::CanFrame& frame, TimePoint now) noexcept {
  ++counters.frames_in;
  const Outbox::Batch batch(outbox);
  now = clamp_time(now);
  advance(now);  // state changes below apply from `now`
  outbox.release(now);

  const codec::IdParse id = codec::parse_id(frame.id, frame.extended);
  if (!id.id) {
    if (id.error != codec::IdError::UnknownPacket) {
      ++counters.not_pmu;
      return;
    }
    const auto to = codec::address_of_id(frame.id);
    if (!addressed_to_us(to))
      ++counters.other_address;
    else if (outbox.faults().silent)
      ++counters.ignored_silent;
    else
      ++counters.unknown_packet;
    return;
  }
  if (!addressed_to_us(id.id->address)) {
    ++counters.other_address;
    return;
  }
  if (outbox.faults().silent) {
    ++counters.ignored_silent;
    return;
  }
  // v1.9 6.5: 0x0F exists from firmware 1.14; older units do not know the packet at all.
  if (id.id->packet == PacketId::MeasurementRequest && !codec::supports(firmware, codec::Feature::MeasurementRequest)) {
    ++counters.unsupported;
    return;
  }
  const auto msg = codec::decode(frame, firmware);
  if (!msg) {
    if (msg.error().kind == codec::DecodeErrorKind::WrongLength)
      ++counters.wrong_length;
    else
      ++counters.malformed;
    return;
  }
  handle(*msg, now);
}

void ModelState::handle(const codec::PmuMessage& msg, TimePoint now) noexcept {
  // Unreachable while decode only yields table 1 packets; checked here so that the switch
  // below can name every packet and the compiler points at it when the table grows.
  if (!codec::is_known_packet(static_cast<std::uint8_t>(msg.packet))) {
    ++counters.unknown_packet;
    return;
  }
  switch (msg.packet) {
    case PacketId::Voltages:
    case PacketId::Currents:
    case PacketId::BatteryEnergy:
    case PacketId::Temperatures:
    case PacketId::Status:
      // With data these are another unit's telemetry; zero-length is a get (5.1..5.5).
      if (!msg.request) {
        ++counters.not_commands;
        return;
      }
      // Packet ids 0x00..0x04 are the bit numbers of their group (tables 7 and 13).
      send_telemetry(static_cast<std::uint8_t>(1u << static_cast<unsigned>(msg.packet)), now);
      break;
    case PacketId::MeasurementRequest: {
      // Table 7: zero data bytes = every measurement; MR = 0 asks for nothing, and gets it.
      const auto* mr = payload<codec::MeasurementRequest>(msg);
      send_telemetry(mr ? mr->groups : codec::group_bit::All, now);
      break;
    }
    case PacketId::Outputs:
      if (msg.request) {
        send(codec::encode_outputs_reply(outputs, address), now);
      } else if (const auto* o = payload<codec::OutputStates>(msg)) {
        outputs = o->mask;  // bits 4..7 "don't care": the decoder already dropped them
      }
      break;
    case PacketId::EnableOutputs:
      if (const auto* e = payload<codec::EnableOutputs>(msg)) outputs = static_cast<std::uint8_t>(outputs | e->mask);
      break;
    case PacketId::DisableOutputs:
      if (const auto* d = payload<codec::DisableOutputs>(msg)) outputs = static_cast<std::uint8_t>(outputs & ~d->mask);
      break;
    case PacketId::Generation:
      if (msg.request) {
        send(codec::encode_generation_reply(generation_on, address), now);
      } else if (const auto* g = payload<codec::GenerationState>(msg)) {
        generation_on = g->enabled;
      }
      break;
    case PacketId::EngineStart:
      // Chosen: the starter does not engage on an engine already cranking or running (the
      // cranking timer is not restarted either), nor while the starter module reports
      // not ready (flag register 1 bit 7).
      if (engine != EngineState::Stopped || !plant.starter_ready) {
        ++counters.ignored_commands;
        return;
      }
      engine = EngineState::Cranking;
      crank_since = now;
      break;
    case PacketId::EngineStop:
      // 5.23 stops cranking only; the PMU has no way to stop a running engine.
      if (engine == EngineState::Cranking) engine = EngineState::Stopped;
      break;
    case PacketId::Reset: restart(now); break;
    case PacketId::Serial:
    case PacketId::Firmware:
      if (!msg.request) {  // another unit's answer
        ++counters.not_commands;
        return;
      }
      if (msg.packet == PacketId::Serial) {
        send(codec::encode_serial(serial_number, address), now);
      } else {
        const codec::FirmwareInfo info{firmware.major, firmware.minor, build_date.day, build_date.month,
                                       build_date.year};
        send(codec::encode_firmware(info, address), now);
      }
      break;
    case PacketId::AvionicsVoltage:
    case PacketId::PayloadVoltage:
    case PacketId::ServoVoltage:
    case PacketId::BatteryVoltage:
    case PacketId::PacketPeriod:
    case PacketId::PacketsStreamed:
    case PacketId::TemperatureOffset:
    case PacketId::UpperTemperatureLimit:
    case PacketId::PowerUpState:
    case PacketId::CrankingTime:
    case PacketId::CanAddress: handle_parameter(msg, now); return;  // counts for itself
  }
  ++counters.handled;
}

void ModelState::handle_parameter(const codec::PmuMessage& msg, TimePoint now) noexcept {
  const auto parameter = codec::parameter_from_packet(msg.packet);
  if (!parameter) {  // unreachable while decode only yields table 1 packets
    ++counters.unknown_packet;
    return;
  }
  if (msg.request) {
    ++counters.handled;
    send(codec::encode_parameter_reply(*parameter, params.raw(*parameter), address), now);
    return;
  }
  const auto* set = payload<codec::ParameterValue>(msg);
  if (!set) {
    ++counters.malformed;
    return;
  }
  // The spec's range (and for S0 the bits this firmware defines) is the codec's: a value
  // to_raw refuses is one no conforming master could send, and the unit keeps its value.
  // Chosen: bits marked "don't care" (PS 5..7, S0 7) also make the set ignored, so a
  // service reading back sees exactly what it wrote or the old value.
  const auto valid = codec::to_raw(*parameter, set->value, firmware);
  if (!valid || *valid != set->raw) {
    ++counters.rejected_sets;
    return;
  }
  if (outbox.faults().ignored_set == *parameter) {
    ++counters.ignored_sets;
    return;
  }
  ++counters.handled;
  params.set_raw(*parameter, set->raw);
  switch (*parameter) {
    case codec::Parameter::PacketPeriod:
      next_stream = now + packet_period();  // the new period starts now
      break;
    case codec::Parameter::UpperTemperatureLimit: update_thermal(); break;
    case codec::Parameter::CanAddress:
      // Chosen: the new address applies at once (the spec does not say it waits for a
      // restart); the unit answers on it from the next frame.
      address = static_cast<std::uint16_t>(set->raw);
      break;
    case codec::Parameter::AvionicsVoltage:
    case codec::Parameter::PayloadVoltage:
    case codec::Parameter::ServoVoltage: break;  // they show in the next measurement
    case codec::Parameter::PowerUpState: break;  // applies at the next reset
    case codec::Parameter::BatteryVoltage:
    case codec::Parameter::PacketsStreamed:
    case codec::Parameter::TemperatureOffset:
    case codec::Parameter::CrankingTime:
      break;  // read where they are used (streaming, readings, cranking), nothing to redo
  }
}

}  // namespace pmu::sim::detail
