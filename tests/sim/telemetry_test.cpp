// Telemetry: streaming (tables 12, 13), the 0x0F measurement request per firmware (table 7,
// v1.9 6.5), flag register 0 bit 6 per firmware (v1.9 6.8), measurements that follow the
// outputs (tables 2, 3), clamping into the fields' ranges, 1.12 external sensors (6.1).
#include <gtest/gtest.h>

#include <cmath>

#include "pmu/codec/telemetry.hpp"
#include "sim_harness.hpp"

namespace pmu::sim::test {
namespace {

namespace gb = codec::group_bit;
namespace ob = codec::output_bit;

// ---- streaming ---------------------------------------------------------------------------
struct StreamCase {
  std::uint8_t ps;
  std::uint32_t pp;  // 0.1 s
  std::vector<PacketId> burst;
};

const StreamCase kStreams[] = {
    {gb::Voltages, 5, {PacketId::Voltages}},
    {gb::Currents | gb::Status, 10, {PacketId::Currents, PacketId::Status}},
    {gb::All,
     1,
     {PacketId::Voltages, PacketId::Currents, PacketId::BatteryEnergy, PacketId::Temperatures, PacketId::Status}},
    {gb::BatteryEnergy | gb::Temperatures, 25, {PacketId::BatteryEnergy, PacketId::Temperatures}},
    {0, 3, {}},
};

TEST(SimStreaming, PeriodAndSelection) {
  for (const auto& c : kStreams) {
    SCOPED_TRACE("PS " + std::to_string(c.ps) + " PP " + std::to_string(c.pp));
    Harness h;
    h.deliver(codec::encode_set(Parameter::PacketsStreamed, c.ps, 1));
    h.deliver(codec::encode_set(Parameter::PacketPeriod, c.pp / 10.0, 1));
    const TimePoint set_at = h.now;
    const Duration period = 100ms * c.pp;
    h.run(period * 3 + period / 2, 10ms);

    ASSERT_EQ(h.sent.size(), 3 * c.burst.size());
    for (std::size_t i = 0; i < h.sent.size(); ++i) {
      const auto burst = static_cast<int>(i / c.burst.size()) + 1;
      EXPECT_EQ(h.sent[i].at, set_at + period * burst) << "frame " << i;
    }
    const auto msgs = h.take();
    ASSERT_EQ(msgs.size(), 3 * c.burst.size());
    for (std::size_t i = 0; i < msgs.size(); ++i) EXPECT_EQ(msgs[i].packet, c.burst[i % c.burst.size()]);
    for (const auto& m : msgs) EXPECT_EQ(m.address, 1);
  }
}

TEST(SimStreaming, BurstsAtEachPeriodFromPowerUp) {
  Harness h(DeviceConfig{});  // factory: PS 0x1F, PP 1.0 s
  h.run(999ms, 1ms);
  EXPECT_TRUE(h.sent.empty());
  h.run(1ms, 1ms);
  ASSERT_EQ(h.sent.size(), 5u);
  for (const auto& s : h.sent) EXPECT_EQ(s.at, h.start + 1s);
  h.run(2s, 7ms);  // ticks that do not divide the period: no drift, one burst per period
  ASSERT_EQ(h.sent.size(), 15u);
  EXPECT_LT(h.sent[5].at - (h.start + 2s), 7ms);
  EXPECT_LT(h.sent[10].at - (h.start + 3s), 7ms);
  EXPECT_EQ(
      packets(h.take()),
      (std::vector<PacketId>{PacketId::Voltages, PacketId::Currents, PacketId::BatteryEnergy, PacketId::Temperatures,
                             PacketId::Status, PacketId::Voltages, PacketId::Currents, PacketId::BatteryEnergy,
                             PacketId::Temperatures, PacketId::Status, PacketId::Voltages, PacketId::Currents,
                             PacketId::BatteryEnergy, PacketId::Temperatures, PacketId::Status}));
}

TEST(SimStreaming, NewPeriodStartsWhenSet) {
  Harness h(DeviceConfig{});
  h.run(500ms);
  h.deliver(codec::encode_set(Parameter::PacketPeriod, 2.0, 1));
  h.run(1900ms);
  EXPECT_TRUE(h.sent.empty()) << "the 1 s deadline was replaced by one 2 s after the set";
  h.run(100ms);
  EXPECT_EQ(h.sent.size(), 5u);
}

TEST(SimStreaming, StallResumesWithoutBurst) {
  // The platform did not tick for 5.5 s: one burst now, then the normal period again.
  Harness h(DeviceConfig{});
  h.tick_at(5500ms);
  EXPECT_EQ(h.sent.size(), 5u);
  h.tick_at(5510ms);
  EXPECT_EQ(h.sent.size(), 5u);
  h.tick_at(6499ms);
  EXPECT_EQ(h.sent.size(), 5u);
  h.tick_at(6500ms);
  EXPECT_EQ(h.sent.size(), 10u);
}

TEST(SimStreaming, NextDeadlineIsTheNextBurst) {
  Harness h(DeviceConfig{});
  EXPECT_EQ(h.pmu.next_deadline(), h.start + 1s);
  h.run(1s);
  EXPECT_EQ(h.pmu.next_deadline(), h.start + 2s);
}

// ---- 0x0F measurement request, from firmware 1.14 ----------------------------------------
struct RequestCase {
  codec::FirmwareVersion fw;
  std::optional<std::uint8_t> mr;  // nullopt: zero-length ("all")
  std::vector<PacketId> replies;
};

const std::vector<PacketId> kAll = {PacketId::Voltages, PacketId::Currents, PacketId::BatteryEnergy,
                                    PacketId::Temperatures, PacketId::Status};

const RequestCase kRequests[] = {
    {kFw112, std::nullopt, {}},
    {kFw112, gb::All, {}},
    {{1, 13}, gb::Voltages, {}},
    {kFw114, std::nullopt, kAll},
    {kFw114, gb::Voltages | gb::BatteryEnergy, {PacketId::Voltages, PacketId::BatteryEnergy}},
    {kFw116, gb::Status, {PacketId::Status}},
    {kFw117, 0xE0 | gb::Temperatures, {PacketId::Temperatures}},  // bits 5..7 don't care
    {kFw117, 0x00, {}},
};

TEST(SimMeasurementRequest, PerFirmware) {
  for (const auto& c : kRequests) {
    SCOPED_TRACE(codec::to_string(c.fw) + (c.mr ? " MR " + std::to_string(*c.mr) : " zero-length"));
    Harness h(quiet_config(1, c.fw));
    h.deliver(c.mr ? raw_frame(PacketId::MeasurementRequest, 1, {*c.mr})
                   : raw_frame(PacketId::MeasurementRequest, 1, {}));
    EXPECT_EQ(packets(h.take()), c.replies);
    const bool supported = c.fw >= kFw114;
    EXPECT_EQ(h.pmu.counters().unsupported, supported ? 0u : 1u);
    EXPECT_EQ(h.pmu.counters().handled, supported ? 1u : 0u);
  }
}

// ---- flag register 0 bit 6 ---------------------------------------------------------------
struct Bit6Case {
  codec::FirmwareVersion fw;
  bool start_button, soa_shutdown;
  bool bit6;
};

const Bit6Case kBit6[] = {
    {kFw112, true, false, true},  {kFw112, false, true, false},  {kFw115, true, false, true},
    {kFw115, false, true, false}, {kFw116, true, false, false},  {kFw116, false, true, true},
    {kFw117, false, true, true},  {kFw117, false, false, false},
};

TEST(SimStatus, Bit6MeaningPerFirmware) {
  for (const auto& c : kBit6) {
    SCOPED_TRACE(codec::to_string(c.fw) + " button " + std::to_string(c.start_button) + " soa " +
                 std::to_string(c.soa_shutdown));
    Harness h(quiet_config(1, c.fw));
    Plant p;
    p.start_button = c.start_button;
    p.soa_shutdown = c.soa_shutdown;
    h.pmu.set_plant(p, h.now);
    h.deliver(codec::encode_get(PacketId::Status, 1));
    ASSERT_EQ(h.sent.size(), 1u);
    EXPECT_EQ((h.sent[0].frame.data[2] & 0x40) != 0, c.bit6);
    const auto s = h.get<codec::Status>(PacketId::Status);
    ASSERT_TRUE(s);
    const codec::Status model = h.pmu.telemetry().status;
    EXPECT_EQ(model.soa_shutdown || model.start_button, c.bit6) << "the other meaning reads false";
    if (c.fw >= kFw116) {
      EXPECT_EQ(s->soa_shutdown, c.bit6);
      EXPECT_FALSE(s->start_button);
    } else {
      EXPECT_EQ(s->start_button, c.bit6);
      EXPECT_FALSE(s->soa_shutdown);
    }
  }
}

TEST(SimStatus, FlagsAndOutputs) {
  Harness h;
  Plant p;
  p.payload_shed = true;
  p.starter_ready = true;
  h.pmu.set_plant(p, h.now);
  h.deliver(codec::encode_set_outputs(ob::AvionicsServo | ob::ChargerB, 1));
  h.deliver(codec::encode_generation(false, 1));
  const auto s = h.get<codec::Status>(PacketId::Status);
  ASSERT_TRUE(s);
  EXPECT_EQ(s->outputs, ob::AvionicsServo | ob::ChargerB);
  EXPECT_FALSE(s->generation_enabled);
  EXPECT_TRUE(s->payload_shed);
  EXPECT_TRUE(s->starter_ready);
  EXPECT_FALSE(s->thermal_shutdown);
}

// ---- 1.12: external temperatures and the starter-ready flag (v1.9 6.1) ---------------------
struct SensorCase {
  codec::FirmwareVersion fw;
  bool external;
};
const SensorCase kSensors[] = {{{1, 11}, false}, {kFw112, true}, {kFw117, true}};

TEST(SimTemperatures, ExternalSensorsFrom112) {
  for (const auto& c : kSensors) {
    SCOPED_TRACE(codec::to_string(c.fw));
    Harness h(quiet_config(1, c.fw));
    Plant p;
    p.battery_a_temperature = 31;
    p.battery_b_temperature = 32;
    p.generator_temperature = 60;
    p.starter_ready = true;
    h.pmu.set_plant(p, h.now);
    const auto t = h.get<codec::Temperatures>(PacketId::Temperatures);
    ASSERT_TRUE(t);
    EXPECT_DOUBLE_EQ(t->internal, 35);
    EXPECT_DOUBLE_EQ(t->starter, 25);
    // Decoded as firmware 1.17 would be: the raw byte is -128 ("no sensor") before 1.12.
    h.deliver(codec::encode_get(PacketId::Temperatures, 1));
    const auto raw = codec::decode(h.sent.at(0).frame, kFw117);
    ASSERT_TRUE(raw.ok());
    const auto& all = std::get<codec::Temperatures>(raw->payload);
    EXPECT_EQ(std::isnan(all.battery_a), !c.external);
    EXPECT_EQ(std::isnan(all.generator), !c.external);
    if (c.external) {
      EXPECT_DOUBLE_EQ(all.battery_a, 31);
      EXPECT_DOUBLE_EQ(all.battery_b, 32);
      EXPECT_DOUBLE_EQ(all.generator, 60);
    }
    EXPECT_EQ((h.sent[0].frame.data[0]), 35);
    h.sent.clear();
    h.deliver(codec::encode_get(PacketId::Status, 1));
    EXPECT_EQ((h.sent.at(0).frame.data[3] & 0x80) != 0, c.external) << "starter ready flag";
  }
}

// ---- measurements follow the outputs (tables 2, 3) ---------------------------------------
struct OutputCase {
  std::uint8_t outputs;
  double avionics_v, servo_v, payload_v;
  double avionics_a, servo_a, payload_a;
};

// Set points V_A 15.0, V_S 7.5, V_P 20.0; loads 1.5 A, 0.5 A, 3.0 A.
const OutputCase kOutputs[] = {
    {0, 0, 0, 0, 0, 0, 0},
    {ob::AvionicsServo, 15.0, 7.5, 0, 1.5, 0.5, 0},
    {ob::Payload, 0, 0, 20.0, 0, 0, 3.0},
    {ob::AvionicsServo | ob::Payload, 15.0, 7.5, 20.0, 1.5, 0.5, 3.0},
    {ob::ChargerA | ob::ChargerB, 0, 0, 0, 0, 0, 0},
};

TEST(SimMeasurements, DisabledOutputReadsZero) {
  for (const auto& c : kOutputs) {
    SCOPED_TRACE("outputs " + std::to_string(c.outputs));
    Harness h;
    Plant p;
    p.avionics_load = 1.5;
    p.servo_load = 0.5;
    p.payload_load = 3.0;
    h.pmu.set_plant(p, h.now);
    h.deliver(codec::encode_set(Parameter::AvionicsVoltage, 15.0, 1));
    h.deliver(codec::encode_set(Parameter::ServoVoltage, 7.5, 1));
    h.deliver(codec::encode_set(Parameter::PayloadVoltage, 20.0, 1));
    h.deliver(codec::encode_set_outputs(c.outputs, 1));
    const auto v = h.get<codec::Voltages>(PacketId::Voltages);
    const auto a = h.get<codec::Currents>(PacketId::Currents);
    ASSERT_TRUE(v && a);
    EXPECT_DOUBLE_EQ(v->avionics, c.avionics_v);
    EXPECT_DOUBLE_EQ(v->servo, c.servo_v);
    EXPECT_DOUBLE_EQ(v->payload, c.payload_v);
    EXPECT_DOUBLE_EQ(a->avionics, c.avionics_a);
    EXPECT_DOUBLE_EQ(a->servo, c.servo_a);
    EXPECT_DOUBLE_EQ(a->payload, c.payload_a);
  }
}

// Generator speed and voltage (table 6 bytes 0-1, table 2 byte 6).
struct GeneratorCase {
  const char* state;
  bool running, cranking, generation;
  std::uint16_t rpm;
  double volts;
};
const GeneratorCase kGenerator[] = {
    {"stopped", false, false, true, 0, 0},
    {"running, generating", true, false, true, 5200, 48.0},
    {"running, generation off", true, false, false, 5200, 0},
    {"cranking", false, true, true, 300, 0},
};

TEST(SimMeasurements, GeneratorFollowsEngineAndGeneration) {
  for (const auto& c : kGenerator) {
    SCOPED_TRACE(c.state);
    Harness h;
    Plant p;
    p.engine_rpm = 5200;
    p.cranking_rpm = 300;
    p.generator_voltage = 48.0;
    p.engine_starts_after.reset();
    h.pmu.set_plant(p, h.now);
    if (c.running) h.pmu.set_engine_running(true, h.now);
    if (c.cranking) h.deliver(codec::encode_engine_start(1));
    h.deliver(codec::encode_generation(c.generation, 1));
    const auto s = h.get<codec::Status>(PacketId::Status);
    const auto v = h.get<codec::Voltages>(PacketId::Voltages);
    ASSERT_TRUE(s && v);
    EXPECT_EQ(s->generator_rpm, c.rpm);
    EXPECT_DOUBLE_EQ(v->generator, c.volts);
  }
}

// ---- clamping into the field's range ------------------------------------------------------
TEST(SimMeasurements, ClampedIntoFieldRange) {
  Harness h;
  Plant p;
  p.battery_a_voltage = 30.0;        // table 2: 0..25.0
  p.battery_b_voltage = -1.0;        // below 0
  p.output_28v_load = -20.0;         // table 3: -12.5..12.5
  p.avionics_load = 14.0;            // 0..10.0
  p.internal_temperature = -200.0;   // table 5: -127..127 and "no sensor"
  p.battery_a_temperature = -128.0;  // a real -128 is not "no sensor": -127
  p.battery_b_temperature = 300.0;
  p.starter_temperature = -60.0;  // -49..127
  p.engine_rpm = 65535;
  h.pmu.set_plant(p, h.now);
  h.pmu.set_engine_running(true, h.now);
  const auto v = h.get<codec::Voltages>(PacketId::Voltages);
  const auto a = h.get<codec::Currents>(PacketId::Currents);
  const auto t = h.get<codec::Temperatures>(PacketId::Temperatures);
  const auto s = h.get<codec::Status>(PacketId::Status);
  ASSERT_TRUE(v && a && t && s);
  EXPECT_DOUBLE_EQ(v->battery_a, 25.0);
  EXPECT_DOUBLE_EQ(v->battery_b, 0.0);
  EXPECT_DOUBLE_EQ(a->output_28v, -12.5);
  EXPECT_DOUBLE_EQ(a->avionics, 10.0);
  EXPECT_DOUBLE_EQ(t->internal, -127.0);
  EXPECT_DOUBLE_EQ(t->battery_a, -127.0);
  EXPECT_DOUBLE_EQ(t->battery_b, 127.0);
  EXPECT_DOUBLE_EQ(t->starter, -49.0);
  EXPECT_EQ(s->generator_rpm, 65535);
  EXPECT_EQ(h.pmu.counters().encode_errors, 0u);
}

// The limits are the codec's telemetry tables, the ranges its encoder refuses beyond: a
// simulated reading can never be an encode error, whichever way the table changes.
template <class Packet>
double table_limit(std::string_view field, bool upper) {
  for (const auto& f : codec::Telemetry<Packet>::fields)
    if (f.name == field) return upper ? f.max() : f.min();
  ADD_FAILURE() << "no field " << field;
  return 0;
}

TEST(SimMeasurements, ClampLimitsAreTheCodecTablesRanges) {
  for (const double far : {1e6, -1e6}) {
    SCOPED_TRACE(far);
    const bool up = far > 0;
    {
      Harness h;
      Plant p;
      p.battery_a_voltage = p.battery_b_voltage = p.output_28v_voltage = p.generator_voltage = far;
      p.avionics_load = p.payload_load = p.servo_load = p.output_28v_load = p.charge_current = far;
      h.pmu.set_plant(p, h.now);
      h.pmu.set_engine_running(true, h.now);
      const auto v = h.get<codec::Voltages>(PacketId::Voltages);
      const auto a = h.get<codec::Currents>(PacketId::Currents);
      ASSERT_TRUE(v && a);
      EXPECT_DOUBLE_EQ(v->battery_a, table_limit<codec::Voltages>("battery_a", up));
      EXPECT_DOUBLE_EQ(v->battery_b, table_limit<codec::Voltages>("battery_b", up));
      EXPECT_DOUBLE_EQ(v->output_28v, table_limit<codec::Voltages>("output_28v", up));
      EXPECT_DOUBLE_EQ(v->generator, table_limit<codec::Voltages>("generator", up));
      for (const auto& f : codec::Telemetry<codec::Currents>::fields)
        EXPECT_DOUBLE_EQ((*a).*f.member, table_limit<codec::Currents>(f.name, up)) << f.name;
      EXPECT_EQ(h.pmu.counters().encode_errors, 0u);
    }
    {
      Harness h;
      Plant p;
      p.internal_temperature = p.starter_temperature = far;
      p.battery_a_temperature = p.battery_b_temperature = p.generator_temperature = far;
      h.pmu.set_plant(p, h.now);
      const auto t = h.get<codec::Temperatures>(PacketId::Temperatures);
      ASSERT_TRUE(t);
      for (const auto& f : codec::Telemetry<codec::Temperatures>::fields)
        EXPECT_DOUBLE_EQ((*t).*f.member, table_limit<codec::Temperatures>(f.name, up)) << f.name;
      EXPECT_EQ(h.pmu.counters().encode_errors, 0u);
    }
  }
}

TEST(SimMeasurements, NanTemperatureIsSentAsNoSensor) {
  Harness h;
  Plant p;
  p.internal_temperature = std::nan("");  // every temperature has "no sensor" (-128)
  h.pmu.set_plant(p, h.now);
  const auto t = h.get<codec::Temperatures>(PacketId::Temperatures);
  ASSERT_TRUE(t);
  EXPECT_TRUE(std::isnan(t->internal));
  EXPECT_EQ(h.pmu.counters().encode_errors, 0u);
}

}  // namespace
}  // namespace pmu::sim::test
