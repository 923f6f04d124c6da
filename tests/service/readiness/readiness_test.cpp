// The readiness rules (readiness_rules.hpp, interface.md 1.7) from the table of situations a
// flight-test engineer meets, and the tracker that applies them to what the sessions report:
// a report on every change and once a second, never more often for an unchanged situation.
#include <gtest/gtest.h>

#include "pmu/baseline/config_file.hpp"
#include "pmu/readiness/readiness_tracker.hpp"
#include "pmu/transport/clock.hpp"
#include "support/recording_sink.hpp"

namespace pmu::service::test {
namespace {

using namespace std::chrono_literals;
using alarms::AlarmState;
using alarms::Code;
using alarms::Severity;
using Key = std::tuple<std::string, DeviceKind, std::uint16_t>;

DeviceView online(std::optional<codec::FirmwareVersion> fw = codec::FirmwareVersion{1, 17},
                  std::optional<codec::FirmwareVersion> min = std::nullopt) {
  DeviceView d;
  d.state = HealthState::Online;
  d.firmware = fw;
  d.min_firmware = min;
  return d;
}

AlarmReport alarm(Code code, AlarmState state, std::uint16_t device = 1) {
  AlarmReport a;
  a.bus = "can0";
  a.device = device;
  a.code = code;
  a.severity = alarms::spec_of(code).severity;
  a.state = state;
  a.message = std::string(alarms::spec_of(code).subject);
  return a;
}

struct Situation {
  const char* what;
  ReadinessInput input;
  bool ready;
  std::vector<std::string> codes;  // the reasons' codes, in order
};

TEST(ReadinessRules, EachSituationGivesItsReasonsWorstFirst) {
  const Situation cases[] = {
      {"everything online", {{{Key{"can0", DeviceKind::Pmu, 1}, online()}}, {}}, true, {}},
      {"a PMU not online",
       {{{Key{"can0", DeviceKind::Pmu, 1}, online()},
         {Key{"can0", DeviceKind::Pmu, 2},
          [] {
            auto d = online();
            d.state = HealthState::Offline;
            return d;
          }()}},
        {}},
       false,
       {"device_not_online"}},
      {"never heard (UNKNOWN) is not online",
       {{{Key{"can0", DeviceKind::Battery, 2},
          [] {
            auto d = online(std::nullopt);
            d.state = HealthState::Unknown;
            return d;
          }()}},
        {}},
       false,
       {"device_not_online"}},
      {"bus error-passive: once per bus",
       {{{Key{"can0", DeviceKind::Pmu, 1},
          [] {
            auto d = online();
            d.bus_state = transport::BusState::ErrorPassive;
            return d;
          }()},
         {Key{"can0", DeviceKind::Pmu, 2},
          [] {
            auto d = online();
            d.bus_state = transport::BusState::ErrorPassive;
            return d;
          }()}},
        {}},
       false,
       {"bus_not_up"}},
      {"bus error-warning is a warning",
       {{{Key{"can0", DeviceKind::Pmu, 1},
          [] {
            auto d = online();
            d.bus_state = transport::BusState::ErrorWarning;
            return d;
          }()}},
        {}},
       true,
       {"bus_not_up"}},
      {"firmware below the minimum",
       {{{Key{"can0", DeviceKind::Pmu, 1}, online(codec::FirmwareVersion{1, 12}, codec::FirmwareVersion{1, 14})}}, {}},
       false,
       {"firmware_below_minimum"}},
      {"firmware at the minimum",
       {{{Key{"can0", DeviceKind::Pmu, 1}, online(codec::FirmwareVersion{1, 14}, codec::FirmwareVersion{1, 14})}}, {}},
       true,
       {}},
      {"firmware not read yet is not judged",
       {{{Key{"can0", DeviceKind::Pmu, 1}, online(std::nullopt, codec::FirmwareVersion{1, 14})}}, {}},
       true,
       {}},
      {"an active critical alarm",
       {{{Key{"can0", DeviceKind::Pmu, 1}, online()}},
        {alarm(Code::ThermalShutdown, AlarmState::ActiveUnacknowledged)}},
       false,
       {"thermal_shutdown"}},
      {"an acknowledged critical still active",
       {{{Key{"can0", DeviceKind::Pmu, 1}, online()}}, {alarm(Code::ThermalShutdown, AlarmState::ActiveAcknowledged)}},
       false,
       {"thermal_shutdown"}},
      {"a critical cleared but not acknowledged",
       {{{Key{"can0", DeviceKind::Pmu, 1}, online()}},
        {alarm(Code::ThermalShutdown, AlarmState::ClearedUnacknowledged)}},
       false,
       {"thermal_shutdown"}},
      {"a critical back to NORMAL",
       {{{Key{"can0", DeviceKind::Pmu, 1}, online()}}, {alarm(Code::ThermalShutdown, AlarmState::Normal)}},
       true,
       {}},
      {"an active warning lets it fly",
       {{{Key{"can0", DeviceKind::Pmu, 1}, online()}}, {alarm(Code::PayloadShed, AlarmState::ActiveUnacknowledged)}},
       true,
       {"payload_shed"}},
      {"critical before warning, whatever the device",
       {{{Key{"can0", DeviceKind::Pmu, 1}, online()}},
        {alarm(Code::PayloadShed, AlarmState::ActiveUnacknowledged, 1),
         alarm(Code::ThermalShutdown, AlarmState::ActiveUnacknowledged, 9)}},
       false,
       {"thermal_shutdown", "payload_shed"}},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.what);
    const auto reasons = readiness_reasons(c.input);
    std::vector<std::string> codes;
    bool ready = true;
    for (const auto& r : reasons) {
      codes.push_back(r.code);
      ready = ready && r.severity != Severity::Critical;
      EXPECT_LE(r.message.size(), 42u) << r.message;
      EXPECT_LE(r.description.size(), 127u) << r.description;
      EXPECT_FALSE(r.message.empty());
    }
    EXPECT_EQ(ready, c.ready);
    EXPECT_EQ(codes, c.codes);
  }
}

TEST(ReadinessRules, MessagesNameTheDeviceAndFitAnAutopilotsPrearmText) {
  ReadinessInput in;
  auto d = online(codec::FirmwareVersion{1, 12}, codec::FirmwareVersion{1, 14});
  in.devices[Key{"avionics_can", DeviceKind::Pmu, 65534}] = d;
  d = online();
  d.state = HealthState::Stale;
  in.devices[Key{"can0", DeviceKind::Mppt, 3}] = d;
  const auto reasons = readiness_reasons(in);
  ASSERT_EQ(reasons.size(), 2u);
  EXPECT_EQ(reasons[0].message, "PMU 65534 firmware 1.12 < 1.14");
  EXPECT_EQ(reasons[0].bus, "avionics_can");
  EXPECT_EQ(reasons[1].message, "MPPT 3 on can0 STALE");
  EXPECT_EQ(reasons[1].source, alarms::DeviceKind::Mppt);
}

// ---- the inputs the rules read ----------------------------------------------------------------

constexpr std::uint8_t V = codec::group_bit::Voltages, C = codec::group_bit::Currents,
                       T = codec::group_bit::Temperatures, S = codec::group_bit::Status;
const auto t0 = std::chrono::steady_clock::time_point{} + 100s;

// An ONLINE PMU whose alarms read voltages, temperatures and status, monitoring `monitored`,
// with each packet of `received` last come at t0 - `age`; stale after 3 s.
DeviceView fed(std::uint8_t monitored, std::uint8_t received, std::chrono::milliseconds age = 0ms,
               bool streaming = true) {
  DeviceView d = online();
  d.packets_needed = V | T | S;
  d.packets_monitored = monitored;
  d.streaming = streaming;
  d.max_age = 3s;
  for (std::size_t i = 0; i < 5; ++i)
    if (received & (1u << i)) d.received[i] = t0 - age;
  return d;
}

// Unknown is never OK: an alarm with no input holds NORMAL, so a packet the rules read that
// is not monitored, not received or stale is a critical reason of its own (docs/safety.md H6,
// H3).
TEST(ReadinessRules, APacketTheRulesReadThatIsNotFreshIsNotReady) {
  struct ReadinessCase {
    const char* what;
    DeviceView device;
    DeviceKind kind;
    std::vector<std::string> messages;  // the reasons', in order
  };
  const auto with_state = [](DeviceView d, HealthState s) {
    d.state = s;
    return d;
  };
  const ReadinessCase cases[] = {
      {"everything the rules read, fresh", fed(V | C | T | S, V | C | T | S), DeviceKind::Pmu, {}},
      {"fresh at the limit of its age", fed(V | T | S, V | T | S, 3000ms), DeviceKind::Pmu, {}},
      {"polled for voltages and currents only",
       fed(V | C, V | C, 0ms, false),
       DeviceKind::Pmu,
       {"PMU 1 status not monitored", "PMU 1 temperatures not monitored"}},
      {"streaming voltages only",
       fed(V, V),
       DeviceKind::Pmu,
       {"PMU 1 status not monitored", "PMU 1 temperatures not monitored"}},
      {"temperatures never came", fed(V | T | S, V | S), DeviceKind::Pmu, {"PMU 1 temperatures not received"}},
      {"status stale",
       [] {
         auto d = fed(V | T | S, V | T);
         d.received[4] = t0 - 3001ms;
         return d;
       }(),
       DeviceKind::Pmu,
       {"PMU 1 status stale"}},
      {"nothing came",
       fed(V | T | S, 0),
       DeviceKind::Pmu,
       {"PMU 1 status not received", "PMU 1 temperatures not received", "PMU 1 voltages not received"}},
      {"currents are read by no rule", fed(V | T | S, V | T | S), DeviceKind::Pmu, {}},
      {"a PMU not online says that alone",
       with_state(fed(V, V), HealthState::Stale),
       DeviceKind::Pmu,
       {"PMU 1 on can0 STALE"}},
      {"a battery reads no PMU packet", online(std::nullopt), DeviceKind::Battery, {}},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.what);
    ReadinessInput in;
    in.now = t0;
    in.devices[Key{"can0", c.kind, 1}] = c.device;
    const auto reasons = readiness_reasons(in);
    std::vector<std::string> messages;
    for (const auto& r : reasons) {
      messages.push_back(r.message);
      EXPECT_EQ(r.severity, Severity::Critical);
      EXPECT_LE(r.message.size(), 42u) << r.message;
      EXPECT_LE(r.description.size(), 127u) << r.description;
      if (r.code == "input_missing") {
        EXPECT_NE(r.description.find("alarms cannot be judged"), std::string::npos);
      }
    }
    EXPECT_EQ(messages, c.messages);
  }
}

TEST(ReadinessRules, AMissingInputSaysWhatToDoForHowTheServiceGetsIt) {
  ReadinessInput in;
  in.now = t0;
  in.devices[Key{"can0", DeviceKind::Pmu, 65534}] = fed(V | S, V | S);
  in.devices[Key{"can0", DeviceKind::Pmu, 2}] = fed(V | S, V | S, 0ms, false);
  const auto reasons = readiness_reasons(in);
  ASSERT_EQ(reasons.size(), 2u);
  EXPECT_EQ(reasons[0].code, "input_missing");
  EXPECT_EQ(reasons[0].device, 2);
  EXPECT_EQ(reasons[0].message, "PMU 2 temperatures not monitored");
  EXPECT_EQ(reasons[0].description,
            "The service does not poll it, so its alarms cannot be judged: add it to the device's packets: in the "
            "service's config.");
  EXPECT_EQ(reasons[1].message, "PMU 65534 temperatures not monitored");
  EXPECT_EQ(reasons[1].description,
            "The PMU does not stream it, so its alarms cannot be judged: add it to packets_streamed (pmuctl config "
            "set).");
}

// ---- drift from a baseline file ---------------------------------------------------------------

baseline::ConfigFile baseline_text(const std::string& text) {
  auto f = baseline::read_config_file(text);
  EXPECT_TRUE(f.ok()) << (f.ok() ? "" : f.error().message);
  return f.ok() ? *f : baseline::ConfigFile{};
}

// A PMU online at firmware 1.17, serial 1001, with `file` as its baseline and every setting
// read as the simulator's factory values (V_A 12.0 V, V_P 12.0 V, T_U 80 degC, outputs 0x0F, ...).
DeviceView pinned_pmu(const std::string& file) {
  DeviceView d = online();
  d.serial = 1001;
  d.baseline = baseline_text(file);
  d.baseline_file = "/etc/pmu-dds/pmu1.yaml";
  ConfigState c;
  const std::uint32_t factory[] = {120, 120, 60, 252, 10, 0x1F, 128, 80, 0x0F, 50, 1};
  for (std::size_t i = 0; i < codec::kParameterCount; ++i) c.raw[i] = factory[i];
  c.outputs = 0x0F;
  c.generation_enabled = true;
  d.settings = settings_of(c);
  return d;
}

TEST(ReadinessRules, ABaselineMakesDriftAReplacedUnitAndItsFirmwarePinReasons) {
  struct ReadinessCase {
    const char* what;
    DeviceView device;
    std::vector<std::string> codes;
    std::string message;  // of the first reason, when given
  };
  const auto unread = [](DeviceView d, baseline::Setting s) {
    d.settings[s].reset();
    return d;
  };
  const auto firmware = [](DeviceView d, std::uint8_t minor, std::optional<std::uint8_t> config_min) {
    d.firmware = codec::FirmwareVersion{1, minor};
    if (config_min) d.min_firmware = codec::FirmwareVersion{1, *config_min};
    return d;
  };
  const auto serial = [](DeviceView d, std::optional<std::uint16_t> sn) {
    d.serial = sn;
    return d;
  };
  const ReadinessCase cases[] = {
      {"every setting as the file says", pinned_pmu("parameters:\n  avionics_voltage: 12.0\noutputs: 15\n"), {}, ""},
      {"12.04 V is the 12.0 V the wire carries", pinned_pmu("parameters:\n  avionics_voltage: 12.04\n"), {}, ""},
      {"one setting differs",
       pinned_pmu("parameters:\n  avionics_voltage: 22.0\n"),
       {"config_differs"},
       "config differs: avionics_voltage"},
      {"three differ: the names that fit, and how many more",
       pinned_pmu("parameters:\n  avionics_voltage: 22.0\n  payload_voltage: 20.0\n  servo_voltage: 7.0\n"),
       {"config_differs"},
       "config differs: avionics_voltage +2 more"},
      {"a long name with a count takes the shorter lead",
       pinned_pmu("parameters:\n  upper_temperature_limit: 85\n  cranking_time: 3.0\n"),
       {"config_differs"},
       "differs: upper_temperature_limit +1 more"},
      {"outputs and generation are settings too",
       pinned_pmu("outputs: [avionics_servo]\ngeneration_enabled: false\n"),
       {"config_differs"},
       "config differs: outputs +1 more"},
      {"a setting not read yet is no drift",
       unread(pinned_pmu("parameters:\n  avionics_voltage: 22.0\n"), baseline::Setting::AvionicsVoltage),
       {},
       ""},
      {"nothing read yet is no drift",
       [] {
         auto d = pinned_pmu("parameters:\n  avionics_voltage: 22.0\n");
         d.settings = {};
         return d;
       }(),
       {},
       ""},
      {"another unit's serial",
       pinned_pmu("device:\n  serial: 1002\n"),
       {"serial_differs"},
       "PMU 1 serial 1001, baseline 1002"},
      {"the serial not read yet is not judged", serial(pinned_pmu("device:\n  serial: 1002\n"), std::nullopt), {}, ""},
      {"the serial it pins", pinned_pmu("device:\n  serial: 1001\n"), {}, ""},
      {"the baseline's firmware pin is above the unit's",
       firmware(pinned_pmu("device:\n  min_firmware: \"1.16\"\n"), 15, std::nullopt),
       {"firmware_below_minimum"},
       "PMU 1 firmware 1.15 < 1.16"},
      {"the higher of the pin and the config's min_firmware: the config's",
       firmware(pinned_pmu("device:\n  min_firmware: \"1.12\"\n"), 15, 16),
       {"firmware_below_minimum"},
       "PMU 1 firmware 1.15 < 1.16"},
      {"the pin met", firmware(pinned_pmu("device:\n  min_firmware: \"1.15\"\n"), 15, 12), {}, ""},
      {"a replaced unit that also differs: both",
       pinned_pmu("device:\n  serial: 7\nparameters:\n  avionics_voltage: 22.0\n"),
       {"config_differs", "serial_differs"},
       ""},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.what);
    ReadinessInput in;
    in.devices[Key{"can0", DeviceKind::Pmu, 1}] = c.device;
    const auto reasons = readiness_reasons(in);
    std::vector<std::string> codes;
    for (const auto& r : reasons) {
      codes.push_back(r.code);
      EXPECT_EQ(r.severity, Severity::Critical);
      EXPECT_LE(r.message.size(), 42u) << r.message;
      EXPECT_LE(r.description.size(), 127u) << r.description;
    }
    EXPECT_EQ(codes, c.codes);
    if (!c.message.empty() && !reasons.empty()) {
      EXPECT_EQ(reasons[0].message, c.message);
    }
  }
}

// However many settings differ and however long their names and values, the message fits an
// autopilot's pre-arm text and the description names items device->baseline and the fix.
TEST(ReadinessRules, DriftTextsFitTheirBoundsAndSayHowToFix) {
  const auto everything = pinned_pmu(
      "parameters:\n  avionics_voltage: 24.0\n  payload_voltage: 24.0\n  servo_voltage: 12.0\n"
      "  battery_voltage: 20.0\n  packet_period: 25.5\n  packets_streamed: [status]\n  temperature_offset: 0\n"
      "  upper_temperature_limit: 255\n  power_up_state: none\n  cranking_time: 25.5\n  can_address: 9\n"
      "outputs: none\ngeneration_enabled: false\n");
  ReadinessInput in;
  in.devices[Key{"can0", DeviceKind::Pmu, 1}] = everything;
  const auto all = readiness_reasons(in);
  ASSERT_EQ(all.size(), 1u);
  EXPECT_EQ(all[0].message, "config differs: avionics_voltage +12 more");
  EXPECT_LE(all[0].description.size(), 127u);
  EXPECT_EQ(all[0].description.rfind("avionics_voltage 12.0 V->24.0 V; payload_voltage 12.0 V->24.0 V; ", 0), 0u)
      << all[0].description;
  EXPECT_NE(all[0].description.find(" more. pmuctl config diff / apply pmu1.yaml"), std::string::npos)
      << all[0].description;

  in.devices[Key{"can0", DeviceKind::Pmu, 1}] = pinned_pmu("outputs: [payload]\n");
  const auto one = readiness_reasons(in);
  ASSERT_EQ(one.size(), 1u);
  EXPECT_EQ(
      one[0].description,
      "outputs avionics_servo,payload,charger_a,charger_b (0x0F)->payload (0x02). pmuctl config diff / apply pmu1.yaml");

  // A mask whose names do not fit is said by its numbers: the values are always shown.
  struct ReadinessCase {
    const char* what;
    std::string file;
    std::string description;
  };
  const ReadinessCase masks[] = {
      {"outputs alone", "outputs: [avionics_servo, payload, charger_a]\n",
       "outputs 0x0F->0x07. pmuctl config diff / apply pmu1.yaml"},
      {"power_up_state alone",
       "parameters:\n  power_up_state: [avionics_servo, payload, charger_a, "
       "battery_disconnect_detect, payload_shedding, soa_management]\n",
       "power_up_state 0x0F->0x77. pmuctl config diff / apply pmu1.yaml"},
      {"a mask after a value", "parameters:\n  avionics_voltage: 22.0\noutputs: [avionics_servo, payload, charger_a]\n",
       "avionics_voltage 12.0 V->22.0 V; outputs 0x0F->0x07. pmuctl config diff / apply pmu1.yaml"},
  };
  for (const auto& c : masks) {
    SCOPED_TRACE(c.what);
    in.devices[Key{"can0", DeviceKind::Pmu, 1}] = pinned_pmu(c.file);
    const auto r = readiness_reasons(in);
    ASSERT_EQ(r.size(), 1u);
    EXPECT_EQ(r[0].description, c.description);
  }
}

// ---- the tracker ----------------------------------------------------------------------------

BusConfig bus_with_min_firmware() {
  BusConfig b;
  b.name = "can0";
  DeviceConfig d;
  d.address = 1;
  d.min_firmware = codec::FirmwareVersion{1, 16};
  b.devices.push_back(d);
  b.discovered_defaults.min_firmware = codec::FirmwareVersion{1, 14};
  return b;
}

HealthReport health(HealthState s) {
  HealthReport h;
  h.state = s;
  return h;
}

InfoState info(std::uint8_t minor) {
  InfoState i;
  i.firmware.firmware_major = 1;
  i.firmware.firmware_minor = minor;
  i.firmware_known = true;
  return i;
}

// A PMU's packets as its session hands them on; the tracker reads only which packet it is.
void feed(ReadinessTracker& t, const DeviceKey& key, std::initializer_list<codec::PacketId> packets) {
  for (const auto p : packets) {
    codec::PmuMessage m;
    m.packet = p;
    t.on_telemetry(key, m, {});
  }
}
constexpr auto kVoltages = codec::PacketId::Voltages, kCurrents = codec::PacketId::Currents,
               kTemperatures = codec::PacketId::Temperatures, kStatus = codec::PacketId::Status;

std::vector<std::string> messages_of(const ReadinessReport& r, std::uint16_t device) {
  std::vector<std::string> out;
  for (const auto& x : r.reasons)
    if (x.device == device) out.push_back(x.message);
  return out;
}

TEST(ReadinessTracker, HandsOnOnceEachEventItDoesNotWatch) {
  transport::ManualClock clock;
  RecordingSink next;
  ReadinessTracker t({bus_with_min_firmware()}, Timeouts{}.stale_periods, next, clock);
  const auto at = clock.system_now();
  t.on_battery(DeviceKey{"can0", 2, DeviceKind::Battery}, BatteryState{}, at);
  t.on_battery_cells(DeviceKey{"can0", 2, DeviceKind::Battery}, BatteryCellsState{}, at);
  t.on_mppt(DeviceKey{"can0", 0, DeviceKind::Mppt}, MpptState{}, at);
  t.on_readiness(ReadinessReport{});
  t.on_energy(DeviceKey{"can0", 1, DeviceKind::Pmu}, energy::Figures{}, at);
  t.on_bms_energy(DeviceKey{"can0", 2, DeviceKind::Battery}, energy::BmsFigures{}, at);
  const std::pair<const char*, std::size_t> handed_on[] = {
      {"battery", next.batteries.size()},   {"cells", next.cells.size()},   {"mppt", next.mppts.size()},
      {"readiness", next.readiness.size()}, {"energy", next.energy.size()}, {"bms_energy", next.bms_energy.size()},
  };
  for (const auto& [event, count] : handed_on) EXPECT_EQ(count, 1u) << event;
}

TEST(ReadinessTracker, ReportsEveryChangeAndOnceASecondAndPassesEverythingOn) {
  transport::ManualClock clock;
  RecordingSink next;
  ReadinessTracker t({bus_with_min_firmware()}, Timeouts{}.stale_periods, next, clock);
  const DeviceKey pmu1{"can0", 1, DeviceKind::Pmu};
  const DeviceKey found{"can0", 7, DeviceKind::Pmu};  // discovered: the bus's discover: minimum, 1.14
  t.on_health(pmu1, health(HealthState::Unknown));
  ASSERT_EQ(next.readiness.size(), 1u);
  EXPECT_FALSE(next.readiness.back().ready);
  EXPECT_EQ(next.healths.size(), 1u) << "passed on";

  t.on_health(pmu1, health(HealthState::Unknown));
  EXPECT_EQ(next.readiness.size(), 1u) << "unchanged within a second: no report";
  clock.advance(1s);
  t.on_health(pmu1, health(HealthState::Unknown));
  EXPECT_EQ(next.readiness.size(), 2u) << "unchanged, but a second has passed";

  clock.advance(100ms);
  // Its packets come (fresh for 3 s at the default 1 s period, longer than the rest of this
  // test); while it is not ONLINE they change nothing.
  feed(t, pmu1, {kVoltages, kTemperatures, kStatus});
  EXPECT_EQ(next.readiness.size(), 2u);
  t.on_health(pmu1, health(HealthState::Online));
  ASSERT_EQ(next.readiness.size(), 3u) << "a change: at once";
  EXPECT_TRUE(next.readiness.back().ready);
  EXPECT_EQ(next.readiness.back().since, clock.system_now());

  t.on_info(pmu1, info(15));  // the configured minimum of this PMU is 1.16
  ASSERT_EQ(next.readiness.size(), 4u);
  EXPECT_FALSE(next.readiness.back().ready);
  EXPECT_EQ(next.readiness.back().reasons.at(0).code, "firmware_below_minimum");
  EXPECT_EQ(next.infos.size(), 1u);

  feed(t, found, {kVoltages, kTemperatures, kStatus});
  t.on_health(found, health(HealthState::Online));
  t.on_info(found, info(14));
  EXPECT_EQ(t.current().reasons.size(), 1u) << "1.14 meets the discovered minimum";

  t.on_info(pmu1, info(16));
  EXPECT_TRUE(next.readiness.back().ready);

  AlarmReport hot;
  hot.bus = "can0";
  hot.device = 1;
  hot.code = Code::ThermalShutdown;
  hot.severity = Severity::Critical;
  hot.state = AlarmState::ActiveUnacknowledged;
  hot.message = "thermal shutdown";
  t.on_alarm(hot);
  EXPECT_FALSE(next.readiness.back().ready);
  EXPECT_EQ(next.alarms.size(), 1u) << "passed on";
  hot.state = AlarmState::ClearedUnacknowledged;
  t.on_alarm(hot);
  EXPECT_FALSE(next.readiness.back().ready) << "a critical blocks until acknowledged";
  EXPECT_NE(next.readiness.back().reasons.at(0).message.find("unacknowledged"), std::string::npos);
  hot.state = AlarmState::Normal;
  t.on_alarm(hot);
  EXPECT_TRUE(next.readiness.back().ready);

  t.on_health(found, health(HealthState::Offline));
  EXPECT_FALSE(next.readiness.back().ready);
  t.on_gone(found);  // it moved to another address: the old key is no reason any more
  EXPECT_TRUE(next.readiness.back().ready);
  EXPECT_EQ(next.gone.size(), 1u);
}

// The scenario of a PMU polled for voltages and currents only, and of one whose PS is set to
// voltages at run time: neither is READY while its alarms cannot see what they read
// (docs/safety.md H6, H3).
TEST(ReadinessTracker, APmuIsReadyOnlyWhileThePacketsItsAlarmsReadComeFresh) {
  transport::ManualClock clock;
  RecordingSink next;
  BusConfig b;
  b.name = "can0";
  DeviceConfig streamed;  // streaming every packet at 1 s, the defaults
  streamed.address = 1;
  DeviceConfig polled;
  polled.address = 2;
  polled.mode = TelemetryMode::Polling;
  polled.groups = codec::group_bit::Voltages | codec::group_bit::Currents;
  b.devices = {streamed, polled};
  ReadinessTracker t({b}, 3, next, clock);
  const DeviceKey pmu1{"can0", 1, DeviceKind::Pmu}, pmu2{"can0", 2, DeviceKind::Pmu};
  t.on_health(pmu1, health(HealthState::Online));
  t.on_health(pmu2, health(HealthState::Online));
  EXPECT_FALSE(t.current().ready);
  EXPECT_EQ(messages_of(t.current(), 1),
            (std::vector<std::string>{"PMU 1 status not received", "PMU 1 temperatures not received",
                                      "PMU 1 voltages not received"}));

  feed(t, pmu1, {kVoltages, kCurrents, kTemperatures, kStatus});
  feed(t, pmu2, {kVoltages, kCurrents});
  EXPECT_TRUE(messages_of(t.current(), 1).empty());
  EXPECT_EQ(messages_of(t.current(), 2),
            (std::vector<std::string>{"PMU 2 status not monitored", "PMU 2 temperatures not monitored"}));
  EXPECT_FALSE(next.readiness.back().ready) << "polled for voltages and currents only";

  // A verified set of PS to voltages (the session reports the configuration read back): at once.
  ConfigState c;
  c.raw[static_cast<std::size_t>(codec::Parameter::PacketsStreamed)] = codec::group_bit::Voltages;
  t.on_config(pmu1, c);
  EXPECT_EQ(messages_of(next.readiness.back(), 1),
            (std::vector<std::string>{"PMU 1 status not monitored", "PMU 1 temperatures not monitored"}));
  c.raw[static_cast<std::size_t>(codec::Parameter::PacketsStreamed)] = 0xFF;  // bits 5-7 mean nothing
  t.on_config(pmu1, c);
  EXPECT_TRUE(messages_of(next.readiness.back(), 1).empty());

  // Three periods without a packet: stale; it coming again clears that at once.
  clock.advance(3001ms);
  feed(t, pmu1, {kVoltages, kStatus});
  EXPECT_EQ(messages_of(next.readiness.back(), 1), (std::vector<std::string>{"PMU 1 temperatures stale"}));
  feed(t, pmu1, {kTemperatures});
  EXPECT_TRUE(messages_of(next.readiness.back(), 1).empty());

  // PP read as 5 s: three of those before a packet is stale.
  c.raw[static_cast<std::size_t>(codec::Parameter::PacketPeriod)] = 50;
  t.on_config(pmu1, c);
  clock.advance(14s);
  t.on_health(pmu1, health(HealthState::Online));
  EXPECT_TRUE(messages_of(t.current(), 1).empty());
  clock.advance(1001ms);
  t.on_health(pmu1, health(HealthState::Online));
  EXPECT_EQ(messages_of(t.current(), 1),
            (std::vector<std::string>{"PMU 1 status stale", "PMU 1 temperatures stale", "PMU 1 voltages stale"}));
}

}  // namespace
}  // namespace pmu::service::test
