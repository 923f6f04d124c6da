// Control packets: outputs 0x20..0x22 (tables 19..21), generation 0x23 (table 22), engine
// start/stop 0x24/0x25 with the cranking time CT (table 17), reset 0x26 (5.24).
#include <gtest/gtest.h>

#include "sim_harness.hpp"

namespace pmu::sim::test {
namespace {

namespace ob = codec::output_bit;

// ---- outputs -----------------------------------------------------------------------------
struct OutputStep {
  const char* what;
  codec::CanFrame frame;
  std::uint8_t after;
};

codec::CanFrame ok(const codec::Encoded& e) { return e.ok() ? *e : codec::CanFrame{}; }

// One sequence on one unit, starting from S0 = 0x0F (all on).
const OutputStep kOutputSteps[] = {
    {"set payload only", ok(codec::encode_set_outputs(ob::Payload, 1)), ob::Payload},
    {"enable charger A", ok(codec::encode_enable_outputs(ob::ChargerA, 1)), ob::Payload | ob::ChargerA},
    {"enable what is on", ok(codec::encode_enable_outputs(ob::Payload, 1)), ob::Payload | ob::ChargerA},
    {"disable payload", ok(codec::encode_disable_outputs(ob::Payload, 1)), ob::ChargerA},
    {"disable what is off", ok(codec::encode_disable_outputs(ob::ChargerB, 1)), ob::ChargerA},
    {"set with don't-care bits 4..7", raw_frame(PacketId::Outputs, 1, {0xF3}), ob::AvionicsServo | ob::Payload},
    {"enable with don't-care bits", raw_frame(PacketId::EnableOutputs, 1, {0xF8}), 0x0B},
    {"disable with don't-care bits", raw_frame(PacketId::DisableOutputs, 1, {0xF1}), 0x0A},
    {"set none", ok(codec::encode_set_outputs(0, 1)), 0},
    {"broadcast enable all", ok(codec::encode_enable_outputs(ob::All, codec::kBroadcastAddress)), ob::All},
};

TEST(SimOutputs, SetEnableDisableSequence) {
  Harness h;
  for (const auto& step : kOutputSteps) {
    SCOPED_TRACE(step.what);
    h.deliver(step.frame);
    EXPECT_TRUE(h.sent.empty()) << "commands are not answered";
    const auto got = h.get<codec::OutputStates>(PacketId::Outputs);
    ASSERT_TRUE(got);
    EXPECT_EQ(got->mask, step.after);
    EXPECT_EQ(h.get<codec::Status>(PacketId::Status)->outputs, step.after) << "also in flag register 2";
  }
}

// ---- generation --------------------------------------------------------------------------
TEST(SimGeneration, SetAndGet) {
  Harness h;
  EXPECT_TRUE(h.get<codec::GenerationState>(PacketId::Generation)->enabled);  // on at power-up
  h.deliver(codec::encode_generation(false, 1));
  EXPECT_FALSE(h.get<codec::GenerationState>(PacketId::Generation)->enabled);
  EXPECT_FALSE(h.get<codec::Status>(PacketId::Status)->generation_enabled);
  h.deliver(raw_frame(PacketId::Generation, 1, {0xFF}));  // bit 0 decides
  EXPECT_TRUE(h.get<codec::GenerationState>(PacketId::Generation)->enabled);
  h.deliver(raw_frame(PacketId::Generation, 1, {0xFE}));
  EXPECT_FALSE(h.pmu.generation_enabled());
}

// ---- engine start: cranking until it fires, CT elapses, or 0x25 --------------------------
struct CrankCase {
  const char* what;
  std::optional<Duration> starts_after;
  std::uint32_t ct;  // 0.1 s; 0 = no timeout
  Duration just_before, at;
  EngineState before_state, final_state;
};

const CrankCase kCranks[] = {
    {"fires before CT", 2s, 50, 1990ms, 2s, EngineState::Cranking, EngineState::Running},
    {"never fires: CT ends it", std::nullopt, 50, 4990ms, 5s, EngineState::Cranking, EngineState::Stopped},
    {"fires after CT: too late", 6s, 50, 4990ms, 5s, EngineState::Cranking, EngineState::Stopped},
    {"fires exactly at CT", 3s, 30, 2990ms, 3s, EngineState::Cranking, EngineState::Running},
    {"CT 0: no timeout", std::nullopt, 0, 599s, 600s, EngineState::Cranking, EngineState::Cranking},
    {"CT 0: fires late", 40s, 0, 39990ms, 40s, EngineState::Cranking, EngineState::Running},
    {"shortest CT", std::nullopt, 1, 90ms, 100ms, EngineState::Cranking, EngineState::Stopped},
};

TEST(SimEngine, CrankingOutcome) {
  for (const auto& c : kCranks) {
    SCOPED_TRACE(c.what);
    Harness h;
    Plant p;
    p.engine_starts_after = c.starts_after;
    h.pmu.set_plant(p, h.now);
    h.deliver(codec::encode_set(Parameter::CrankingTime, c.ct / 10.0, 1));
    h.deliver(codec::encode_engine_start(1));
    const TimePoint started = h.now;
    EXPECT_EQ(h.pmu.engine_state(), EngineState::Cranking);
    EXPECT_EQ(h.pmu.next_deadline() - started <= c.at, true);
    h.now = started + c.just_before;
    h.pmu.tick(h.now);
    EXPECT_EQ(h.pmu.engine_state(), c.before_state);
    h.now = started + c.at;
    h.pmu.tick(h.now);
    EXPECT_EQ(h.pmu.engine_state(), c.final_state);
    EXPECT_TRUE(h.sent.empty());
  }
}

TEST(SimEngine, OutcomeDoesNotDependOnTickRate) {
  // One tick long after the end lands in the same state as fine ticks.
  Harness h;
  Plant p;
  p.engine_starts_after.reset();
  h.pmu.set_plant(p, h.now);
  h.deliver(codec::encode_engine_start(1));  // CT 5.0 s (factory)
  h.now += 1h;
  h.pmu.tick(h.now);
  EXPECT_EQ(h.pmu.engine_state(), EngineState::Stopped);
}

TEST(SimEngine, StopEndsCrankingOnly) {
  Harness h;
  Plant p;
  p.engine_starts_after.reset();
  h.pmu.set_plant(p, h.now);
  h.deliver(codec::encode_engine_start(1));
  h.run(1s);
  h.deliver(codec::encode_engine_stop(1));
  EXPECT_EQ(h.pmu.engine_state(), EngineState::Stopped);
  h.pmu.set_engine_running(true, h.now);
  h.deliver(codec::encode_engine_stop(1));
  EXPECT_EQ(h.pmu.engine_state(), EngineState::Running) << "5.23 stops the starter, not the engine";
  EXPECT_TRUE(h.sent.empty());
}

struct IgnoredStartCase {
  const char* what;
  bool running, cranking, starter_ready;
};
const IgnoredStartCase kIgnoredStarts[] = {
    {"engine already running", true, false, true},
    {"already cranking", false, true, true},
    {"starter module not ready", false, false, false},
};

TEST(SimEngine, StartIgnored) {
  for (const auto& c : kIgnoredStarts) {
    SCOPED_TRACE(c.what);
    Harness h;
    Plant p;
    p.starter_ready = c.starter_ready;
    p.engine_starts_after.reset();
    h.pmu.set_plant(p, h.now);
    if (c.running) h.pmu.set_engine_running(true, h.now);
    if (c.cranking) h.deliver(codec::encode_engine_start(1));
    const EngineState before = h.pmu.engine_state();
    h.run(4s);
    h.deliver(codec::encode_engine_start(1));
    EXPECT_EQ(h.pmu.counters().ignored_commands, 1u);
    h.run(1s);  // a restarted timer would still be cranking at 5 s
    EXPECT_EQ(h.pmu.engine_state(), c.cranking ? EngineState::Stopped : before);
  }
}

// ---- reset (5.24) ------------------------------------------------------------------------
TEST(SimReset, OutputsToS0EnergiesZeroGenerationOn) {
  Harness h;
  h.deliver(codec::encode_set(Parameter::PowerUpState, 0x05, 1));  // avionics + charger A
  h.deliver(codec::encode_set(Parameter::AvionicsVoltage, 18.0, 1));
  h.deliver(codec::encode_set_outputs(codec::output_bit::Payload, 1));
  h.pmu.set_engine_running(false, h.now);
  h.run(10min, 1s);  // payload draws from the batteries: energies go negative
  h.deliver(codec::encode_generation(false, 1));
  ASSERT_LT(h.get<codec::BatteryEnergy>(PacketId::BatteryEnergy)->battery_a_mah, 0);

  h.deliver(codec::encode_reset(1));
  EXPECT_TRUE(h.sent.empty());
  EXPECT_EQ(h.get<codec::OutputStates>(PacketId::Outputs)->mask, 0x05);
  EXPECT_TRUE(h.get<codec::GenerationState>(PacketId::Generation)->enabled);
  const auto e = h.get<codec::BatteryEnergy>(PacketId::BatteryEnergy);
  EXPECT_EQ(e->battery_a_mah, 0);
  EXPECT_EQ(e->battery_b_mah, 0);
  EXPECT_EQ(h.get_raw(Parameter::AvionicsVoltage), 180u) << "stored parameters survive a reset";
  EXPECT_EQ(h.get_raw(Parameter::PowerUpState), 0x05u);
}

TEST(SimReset, StopsCrankingAndRestartsStreaming) {
  Harness h(DeviceConfig{});  // streams every 1 s
  Plant p;
  p.engine_starts_after.reset();
  h.pmu.set_plant(p, h.now);
  h.run(900ms);
  h.deliver(codec::encode_engine_start(1));
  h.deliver(codec::encode_reset(1));
  EXPECT_EQ(h.pmu.engine_state(), EngineState::Stopped);
  h.run(999ms, 1ms);
  EXPECT_TRUE(h.sent.empty()) << "the period restarts with the unit";
  h.run(1ms, 1ms);
  EXPECT_EQ(h.sent.size(), 5u);
}

}  // namespace
}  // namespace pmu::sim::test
