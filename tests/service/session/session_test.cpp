// The service's device sessions against simulated PMUs on the in-process bus, with a fake
// clock: start-up reading, streaming and polling, health through silence and recovery,
// firmware-dependent polling, bus state, discovery.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "support/harness.hpp"
#include "pmu/codec/encode.hpp"

namespace pmu::service::test {
namespace {

using codec::PacketId;

std::size_t count_sent(const std::vector<codec::PmuMessage>& sent, PacketId p) {
  return static_cast<std::size_t>(
      std::count_if(sent.begin(), sent.end(), [p](const codec::PmuMessage& m) { return m.packet == p; }));
}

TEST(Session, StartUpReadsIdentityAndEveryParameterThenPublishesInfoAndConfig) {
  Harness h(sim_bus({device(1)}), {pmu(1)});
  h.run_for(200ms);
  ASSERT_EQ(h.sink.infos.size(), 1u);
  EXPECT_EQ(h.sink.infos[0].second.serial_number, 4001);
  EXPECT_EQ(h.sink.infos[0].second.firmware.version(), codec::kCurrentFirmware);
  ASSERT_FALSE(h.sink.configs.empty());
  const ConfigState& c = h.sink.configs.back().second;
  EXPECT_TRUE(c.complete());
  EXPECT_DOUBLE_EQ(c.value(codec::Parameter::PacketPeriod), 1.0);
  EXPECT_EQ(c.raw[static_cast<std::size_t>(codec::Parameter::CanAddress)], 1u);
  // One get per stored value: serial, firmware, 11 parameters, outputs, generation.
  const auto sent = h.sent();
  EXPECT_EQ(sent.size(), 15u);
  for (const auto& m : sent) EXPECT_TRUE(m.request);
  EXPECT_TRUE(h.worker().session(1)->ready());
}

TEST(Session, StreamedTelemetryIsPublishedAtThePacketPeriod) {
  Harness h(sim_bus({device(1)}), {pmu(1, codec::kCurrentFirmware, 5)});  // PP 0.5 s
  h.run_for(5000ms);
  for (auto p :
       {PacketId::Voltages, PacketId::Currents, PacketId::BatteryEnergy, PacketId::Temperatures, PacketId::Status}) {
    const auto n = h.sink.count(p, 1);
    EXPECT_GE(n, 9u) << codec::packet_name(p);
    EXPECT_LE(n, 11u) << codec::packet_name(p);
  }
  // Streaming needs nothing from the service after start-up.
  EXPECT_EQ(h.sent().size(), 15u);
  // Values follow the simulator's state.
  for (const auto& t : h.sink.telemetry) {
    if (const auto* v = std::get_if<codec::Voltages>(&t.message.payload)) {
      EXPECT_DOUBLE_EQ(v->avionics, 12.0);  // V_A as stored, output on
    }
  }
}

TEST(Session, SilenceMakesHealthStaleThenOfflineAndRecoveryRereadsEverything) {
  Timeouts t;
  t.stale_periods = 3;
  t.offline_periods = 10;
  Harness h(sim_bus({device(1)}), {pmu(1)}, t);
  h.run_for(3000ms);
  ASSERT_NE(h.sink.last_health(1), nullptr);
  EXPECT_EQ(h.sink.last_health(1)->state, HealthState::Online);

  h.pmus().with_model(1, [](sim::PmuModel& m) {
    auto f = m.faults();
    f.silent = true;
    m.set_faults(f);
  });
  h.run_for(4000ms);
  EXPECT_EQ(h.sink.last_health(1)->state, HealthState::Stale);
  EXPECT_GT(h.sink.last_health(1)->last_frame_age, 3.0);
  h.run_for(7000ms);
  EXPECT_EQ(h.sink.last_health(1)->state, HealthState::Offline);
  // Health keeps being published while the device is silent, so readers see the age grow.
  const auto published = h.sink.healths.size();
  h.run_for(3000ms);
  EXPECT_GE(h.sink.healths.size(), published + 2);

  const auto infos = h.sink.infos.size();
  h.pmus().with_model(1, [](sim::PmuModel& m) {
    auto f = m.faults();
    f.silent = false;
    m.set_faults(f);
  });
  h.run_for(2000ms);
  EXPECT_EQ(h.sink.last_health(1)->state, HealthState::Online);
  EXPECT_EQ(h.sink.last_health(1)->reconnects, 1u);
  EXPECT_EQ(h.sink.infos.size(), infos + 1) << "info re-read after OFFLINE";
}

TEST(Session, OldFirmwareIsPolledWithSingleGets) {
  auto old = pmu(1, codec::FirmwareVersion{1, 12});
  old.parameters.set_raw(codec::Parameter::PacketsStreamed, 0);  // nothing streamed
  Harness h(sim_bus({device(1, TelemetryMode::Polling, 500ms)}), {old});
  h.run_for(300ms);
  h.clear_sent();
  h.run_for(2000ms);
  const auto sent = h.sent();
  EXPECT_EQ(count_sent(sent, PacketId::MeasurementRequest), 0u) << "0x0F does not exist before 1.14";
  EXPECT_GE(count_sent(sent, PacketId::Voltages), 4u);
  EXPECT_GE(count_sent(sent, PacketId::Status), 4u);
  EXPECT_GE(h.sink.count(PacketId::Voltages, 1), 4u);
  EXPECT_GE(h.sink.count(PacketId::Temperatures, 1), 4u);
  // Status decoded with the old meaning of bit 6.
  for (const auto& t : h.sink.telemetry) {
    if (const auto* s = std::get_if<codec::Status>(&t.message.payload)) {
      EXPECT_EQ(s->interpretation.bit6, codec::Bit6Meaning::StartButton);
    }
  }
}

TEST(Session, Firmware114IsPolledWithMeasurementRequests) {
  auto p = pmu(1, codec::FirmwareVersion{1, 14});
  p.parameters.set_raw(codec::Parameter::PacketsStreamed, 0);
  Harness h(sim_bus({device(1, TelemetryMode::Polling, 500ms)}), {p});
  h.run_for(300ms);
  h.clear_sent();
  h.run_for(2000ms);
  const auto sent = h.sent();
  EXPECT_GE(count_sent(sent, PacketId::MeasurementRequest), 4u);
  EXPECT_EQ(count_sent(sent, PacketId::Voltages), 0u);
  EXPECT_GE(h.sink.count(PacketId::Voltages, 1), 4u);
  EXPECT_GE(h.sink.count(PacketId::Status, 1), 4u);
}

TEST(Session, SilentDeviceAtStartTimesOutAndIsRetriedLater) {
  Timeouts t;
  t.retries = 1;
  t.reply = 100ms;
  Harness h(sim_bus({device(9)}), {}, t);  // nobody at address 9
  h.run_for(400ms);
  ASSERT_EQ(h.sent().size(), 2u) << "one get and one retry, then the rest of the round is dropped";
  EXPECT_EQ(h.worker().session(9)->health().timeouts, 1u);
  h.run_for(3000ms);
  EXPECT_GT(h.sent().size(), 2u) << "reading is retried";
  EXPECT_TRUE(h.sink.infos.empty());
}

TEST(Session, BusStateReachesHealth) {
  Harness h(sim_bus({device(1)}), {pmu(1)});
  h.run_for(200ms);
  h.network().set_state(transport::BusState::Down);
  h.run_for(100ms);
  EXPECT_EQ(h.sink.last_health(1)->bus_state, transport::BusState::Down);
  h.network().set_state(transport::BusState::Up);
  h.run_for(100ms);
  EXPECT_EQ(h.sink.last_health(1)->bus_state, transport::BusState::Up);
}

TEST(Session, DiscoveryFindsUnitsByBroadcast) {
  Harness h(sim_bus({}, true), {pmu(5), pmu(300)});
  h.run_for(500ms);
  const auto addrs = h.worker().addresses();
  EXPECT_EQ(addrs, (std::vector<std::uint16_t>{5, 300}));
  const auto sent = h.sent();
  ASSERT_FALSE(sent.empty());
  EXPECT_EQ(sent[0].packet, PacketId::Firmware);
  EXPECT_EQ(sent[0].address, 0xFFFF);
  EXPECT_EQ(h.sink.infos.size(), 2u);
}

TEST(Session, TwoUnitsOnOneBusAreKeptApart) {
  Harness h(sim_bus({device(1), device(2)}), {pmu(1), pmu(2)});
  h.run_for(2500ms);
  EXPECT_GE(h.sink.count(PacketId::Voltages, 1), 2u);
  EXPECT_GE(h.sink.count(PacketId::Voltages, 2), 2u);
  ASSERT_EQ(h.sink.infos.size(), 2u);
  for (const auto& [key, info] : h.sink.infos) EXPECT_EQ(info.serial_number, 4000 + key.address);
}

TEST(Session, TelemetryCarriesTheFrameReceiveTime) {
  Harness h(sim_bus({device(1)}), {pmu(1)});
  h.run_for(1500ms);
  ASSERT_FALSE(h.sink.telemetry.empty());
  const auto t = h.sink.telemetry.back().received;
  const auto now = h.clock().system_now();
  EXPECT_LE(t, now);
  EXPECT_GT(t, now - 600ms);
}

// A streaming unit's telemetry can arrive between the serial and the firmware replies of
// the start-up reading. It must be decoded as "firmware unknown", not as firmware 0.0,
// which would hide the external temperatures (seen in the VM: battery_a read as no sensor).
TEST(Session, TelemetryBetweenSerialAndFirmwareRepliesDecodesTheExternalSensors) {
  RecordingSink sink;
  const auto t0 = std::chrono::steady_clock::time_point{} + 1h;
  DeviceSession s(
      {"sim0", 1}, device(1), Timeouts{}, sink, [](const codec::CanFrame&) { return transport::SendResult{}; }, t0);
  const auto deliver = [&s](const codec::CanFrame& f, SteadyTime t) {
    s.on_frame(*codec::parse_id(f.id, f.extended).id, f, t, {});
  };
  deliver(*codec::encode_serial(4001, 1), t0 + 1ms);
  codec::Temperatures temps;
  temps.internal = 35;
  temps.battery_a = 25;
  temps.battery_b = 24;
  temps.generator = codec::kNoSensor;
  temps.starter = 20;
  deliver(*codec::encode_temperatures(temps, 1), t0 + 2ms);
  ASSERT_EQ(sink.telemetry.size(), 1u);
  const auto* got = std::get_if<codec::Temperatures>(&sink.telemetry[0].message.payload);
  ASSERT_NE(got, nullptr);
  EXPECT_DOUBLE_EQ(got->battery_a, 25.0);
  EXPECT_DOUBLE_EQ(got->battery_b, 24.0);
  EXPECT_TRUE(std::isnan(got->generator));
  EXPECT_FALSE(s.firmware().has_value());
}

}  // namespace
}  // namespace pmu::service::test
