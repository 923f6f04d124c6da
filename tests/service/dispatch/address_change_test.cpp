// A PMU that changes its CAN address stays one device: from the command (or from another
// tool's set) through to what the service publishes (docs/interface.md, "After a CAN address
// change"). The old key gets OFFLINE once and is gone; the new key has the same serial and
// configuration; moving back and forth leaves no instance behind at either address.
#include <gtest/gtest.h>

#include <algorithm>
#include <functional>

#include "support/harness.hpp"
#include "pmu/codec/encode.hpp"
#include "pmu/dispatch/command_service.hpp"

namespace pmu::service::test {
namespace {

using codec::Parameter;

std::uint32_t raw_of(const ConfigState& c, Parameter p) { return c.raw[static_cast<std::size_t>(p)].value_or(0); }

// A harness whose PMU at address 1 (serial 4001) streams every second, plus a command service.
class Moves {
 public:
  explicit Moves(std::vector<DeviceConfig> devices = {device(1)}, std::vector<sim::DeviceConfig> pmus = {pmu(1)},
                 bool discover = false)
      : h(sim_bus(std::move(devices), discover), std::move(pmus)),
        service({&h.worker()}, PolicyConfig{}, Timeouts{}, h.clock(), [this](const CommandReplyData& r) {
          replies.push_back(r);
          if (at_reply) at_reply();
        }) {
    h.worker().on_moved([this](const BusWorker::Moved& m) { moved.push_back(m); });
    h.run_for(2s);
  }

  CommandReplyData command(CommandKind kind, std::uint16_t address, const char* parameter = "", double value = 0) {
    CommandSample s;
    s.request_id = "t-" + std::to_string(replies.size() + 1);
    s.sender = "test";
    s.bus = "sim0";
    s.address = address;
    s.kind = static_cast<std::uint32_t>(kind);
    s.parameter = parameter;
    s.value = value;
    s.confirm = true;
    const auto before = replies.size();
    service.submit(s);
    for (int i = 0; i < 500 && replies.size() == before; ++i) h.run_for(10ms);
    EXPECT_EQ(replies.size(), before + 1) << "exactly one reply";
    return replies.size() > before ? replies.back() : CommandReplyData{};
  }
  CommandReplyData move(std::uint16_t from, std::uint16_t to) {
    return command(CommandKind::SetParameter, from, "can_address", to);
  }

  // The samples published for `address` from event index `since` on.
  std::size_t events_of(std::uint16_t address, std::size_t since) const {
    std::size_t n = 0;
    for (std::size_t i = since; i < h.sink.events.size(); ++i) n += h.sink.events[i].key.address == address ? 1u : 0u;
    return n;
  }
  std::vector<HealthState> health_states(std::uint16_t address, std::size_t since_healths) const {
    std::vector<HealthState> v;
    for (std::size_t i = since_healths; i < h.sink.healths.size(); ++i)
      if (h.sink.healths[i].first.address == address) v.push_back(h.sink.healths[i].second.state);
    return v;
  }
  const InfoState* last_info(std::uint16_t address) const {
    for (auto it = h.sink.infos.rbegin(); it != h.sink.infos.rend(); ++it)
      if (it->first.address == address) return &it->second;
    return nullptr;
  }
  const ConfigState* last_config(std::uint16_t address) const {
    for (auto it = h.sink.configs.rbegin(); it != h.sink.configs.rend(); ++it)
      if (it->first.address == address) return &it->second;
    return nullptr;
  }

  Harness h;
  std::vector<CommandReplyData> replies;
  std::vector<BusWorker::Moved> moved;
  std::function<void()> at_reply;  // runs where the reply is published, inside the worker's turn
  CommandService service;
};

TEST(AddressChange, CommandedMoveGivesTheOldKeyOneOfflineThenDisposesItAndTheNewKeyEverything) {
  Moves m;
  ASSERT_NE(m.last_config(1), nullptr);
  const ConfigState before = *m.last_config(1);
  const auto healths = m.h.sink.healths.size();

  const auto reply = m.move(1, 7);
  ASSERT_EQ(reply.result, CommandResult::Completed) << reply.reason;
  EXPECT_NE(reply.reason.find("from address 1 to 7"), std::string::npos) << reply.reason;

  // Published by the time the reply is: nothing waits for the next packet period. The old
  // key is disposed a moment after its OFFLINE, so that readers take that sample first.
  EXPECT_EQ(m.health_states(1, healths), (std::vector<HealthState>{HealthState::Offline}));
  EXPECT_TRUE(m.h.sink.gone.empty());
  m.h.run_for(DeviceSession::kGoneDelay + 20ms);
  ASSERT_EQ(m.h.sink.gone.size(), 1u);
  EXPECT_EQ(m.h.sink.gone[0], (DeviceKey{"sim0", 1, DeviceKind::Pmu}));
  EXPECT_EQ(m.health_states(1, healths), (std::vector<HealthState>{HealthState::Offline}));
  ASSERT_NE(m.last_info(7), nullptr);
  EXPECT_EQ(m.last_info(7)->serial_number, 4001);
  ASSERT_NE(m.last_config(7), nullptr);
  for (std::size_t i = 0; i < codec::kParameterCount; ++i) {
    const auto p = static_cast<Parameter>(i);
    if (p == Parameter::CanAddress) continue;
    EXPECT_EQ(raw_of(*m.last_config(7), p), raw_of(before, p)) << codec::spec_of(p).name;
  }
  EXPECT_EQ(raw_of(*m.last_config(7), Parameter::CanAddress), 7u);
  EXPECT_EQ(m.h.sink.live_pmus(), (std::vector<std::uint16_t>{7}));

  const auto gone_at = m.h.sink.events.size();
  m.h.run_for(20s);
  EXPECT_EQ(m.events_of(1, gone_at), 0u) << "nothing is published for the old key after it is gone";
  ASSERT_NE(m.h.sink.last_health(7), nullptr);
  EXPECT_EQ(m.h.sink.last_health(7)->state, HealthState::Online);
  EXPECT_EQ(m.h.sink.live_pmus(), (std::vector<std::uint16_t>{7}));
  EXPECT_EQ(m.h.worker().addresses(), (std::vector<std::uint16_t>{7}));
  ASSERT_EQ(m.moved.size(), 1u);
  EXPECT_EQ(m.moved[0].from, 1);
  EXPECT_EQ(m.moved[0].to, 7);
  EXPECT_EQ(m.moved[0].first, 1);
  EXPECT_EQ(m.moved[0].serial, std::optional<std::uint16_t>(4001));
}

TEST(AddressChange, CommandsGoToTheNewAddressAtOnceAndTheOldOneIsNotSeen) {
  Moves m;
  // Where the reply is published, before the worker's turn ends: the next command may come
  // at once, and must find the unit at its new address and nothing at the old one.
  const DeviceSession* at_new = nullptr;
  const DeviceSession* at_old = nullptr;
  m.at_reply = [&] {
    at_new = m.h.worker().session(7);
    at_old = m.h.worker().session(1);
  };
  ASSERT_EQ(m.move(1, 7).result, CommandResult::Completed);
  m.at_reply = nullptr;
  EXPECT_NE(at_new, nullptr);
  EXPECT_EQ(at_old, nullptr);
  const auto serial = m.command(CommandKind::GetSerial, 7);
  EXPECT_EQ(serial.result, CommandResult::Completed) << serial.reason;
  EXPECT_EQ(serial.value_text, "4001");
  const auto old = m.command(CommandKind::GetSerial, 1);
  EXPECT_EQ(old.result, CommandResult::Rejected);
  EXPECT_NE(old.reason.find("device 1 not seen"), std::string::npos) << old.reason;
}

std::size_t stops_to(const Harness& h, std::uint16_t address) {
  std::size_t n = 0;
  for (const auto& f : h.sent_frames()) n += f.id == codec::make_id(codec::PacketId::EngineStop, address);
  return n;
}

// docs/safety.md H4: a stop sent to the address the unit has just left, by someone who had
// not yet read the move's reply, reaches the unit where it is now; other commands to that
// address are still not seen.
TEST(AddressChange, AnEngineStopToTheAddressTheUnitLeftFollowsIt) {
  Moves m;
  ASSERT_EQ(m.move(1, 7).result, CommandResult::Completed);
  m.h.clear_sent();
  const auto stop = m.command(CommandKind::EngineStop, 1);
  EXPECT_EQ(stop.result, CommandResult::Completed) << stop.reason;
  EXPECT_EQ(stop.reason, "stop sent to address 7, where the unit is now (it was 1)");
  EXPECT_EQ(stops_to(m.h, 7), 1u);
  EXPECT_EQ(stops_to(m.h, 1), 0u);
  EXPECT_EQ(m.command(CommandKind::GetSerial, 1).result, CommandResult::Rejected);
  // Moved on again: the stop still finds it.
  ASSERT_EQ(m.move(7, 9).result, CommandResult::Completed);
  m.h.clear_sent();
  EXPECT_EQ(m.command(CommandKind::EngineStop, 1).result, CommandResult::Completed);
  EXPECT_EQ(stops_to(m.h, 9), 1u);
}

// While our own address change waits for its read-back, the unit answers at one of the two
// addresses: a stop goes to both (docs/safety.md H4).
TEST(AddressChange, AnEngineStopDuringAnAddressChangeGoesToBothAddresses) {
  Moves m;
  m.h.recording_bus().drop_data_of = 0x1B;  // the set is lost: the read-back at 7 waits, unanswered
  CommandSample set;
  set.request_id = "move";
  set.sender = "test";
  set.bus = "sim0";
  set.address = 1;
  set.kind = static_cast<std::uint32_t>(CommandKind::SetParameter);
  set.parameter = "can_address";
  set.value = 7;
  set.confirm = true;
  m.service.submit(set);
  m.h.run_for(100ms);
  ASSERT_TRUE(m.replies.empty()) << "the read-back is still waiting";
  m.h.clear_sent();
  const auto stop = m.command(CommandKind::EngineStop, 1);
  EXPECT_EQ(stop.result, CommandResult::Completed) << stop.reason;
  EXPECT_EQ(stop.reason, "stop sent to addresses 1 and 7: its CAN address is being changed");
  EXPECT_EQ(stops_to(m.h, 1), 1u);
  EXPECT_EQ(stops_to(m.h, 7), 1u);
}

TEST(AddressChange, MovingBackAndForthLeavesNoGhostAtEitherAddress) {
  Moves m;
  const std::pair<std::uint16_t, std::uint16_t> steps[] = {{1, 7}, {7, 1}, {1, 7}, {7, 1}};
  for (const auto& [from, to] : steps) {
    const auto reply = m.move(from, to);
    ASSERT_EQ(reply.result, CommandResult::Completed) << from << " -> " << to << ": " << reply.reason;
    m.h.run_for(3s);
    EXPECT_EQ(m.h.sink.live_pmus(), (std::vector<std::uint16_t>{to})) << from << " -> " << to;
    EXPECT_EQ(m.h.worker().addresses(), (std::vector<std::uint16_t>{to}));
    ASSERT_NE(m.h.sink.last_health(to), nullptr);
    EXPECT_EQ(m.h.sink.last_health(to)->state, HealthState::Online);
    ASSERT_NE(m.last_info(to), nullptr);
    EXPECT_EQ(m.last_info(to)->serial_number, 4001);
  }
  EXPECT_EQ(m.h.sink.gone.size(), 4u);
  ASSERT_EQ(m.moved.size(), 4u);
  EXPECT_EQ(m.moved.back().first, 1) << "the session remembers where it started";
}

TEST(AddressChange, BackBeforeTheOldKeyIsDisposedKeepsThatKeyAlive) {
  Moves m;
  ASSERT_EQ(m.move(1, 7).result, CommandResult::Completed);
  ASSERT_EQ(m.move(7, 1).result, CommandResult::Completed);
  EXPECT_TRUE(m.h.sink.gone.empty()) << "both moves within the disposal delay";
  m.h.run_for(2s);
  ASSERT_EQ(m.h.sink.gone.size(), 1u);
  EXPECT_EQ(m.h.sink.gone[0].address, 7);
  EXPECT_EQ(m.h.sink.live_pmus(), (std::vector<std::uint16_t>{1}));
  ASSERT_NE(m.h.sink.last_health(1), nullptr);
  EXPECT_EQ(m.h.sink.last_health(1)->state, HealthState::Online);
}

TEST(AddressChange, SettingTheSameAddressMovesNothing) {
  Moves m;
  const auto reply = m.move(1, 1);
  EXPECT_EQ(reply.result, CommandResult::Completed) << reply.reason;
  m.h.run_for(2s);
  EXPECT_TRUE(m.h.sink.gone.empty());
  EXPECT_TRUE(m.moved.empty());
  EXPECT_EQ(m.h.sink.live_pmus(), (std::vector<std::uint16_t>{1}));
}

// Another tool on the bus sets the unit's CA: the service sees telemetry from a new address,
// asks it its serial once the old address is silent, and follows.
void set_address_by_other_tool(Moves& m, std::uint16_t from, std::uint16_t to) {
  auto tool = m.h.network().attach("other-tool");
  ASSERT_TRUE(tool->send(*codec::encode_parameter_reply(Parameter::CanAddress, to, from), 100ms).ok());
  m.h.settle();
}

TEST(AddressChange, UnitMovedByAnotherToolIsFoundByItsSerialOnceItsOldAddressIsSilent) {
  Moves m;
  const auto healths = m.h.sink.healths.size();
  set_address_by_other_tool(m, 1, 9);
  m.h.run_for(1500ms);
  EXPECT_TRUE(m.h.sink.gone.empty()) << "address 1 is not silent yet (STALE after 3 periods)";
  m.h.run_for(6s);

  ASSERT_EQ(m.h.sink.gone.size(), 1u);
  EXPECT_EQ(m.h.sink.gone[0].address, 1);
  const auto old = m.health_states(1, healths);
  ASSERT_FALSE(old.empty());
  EXPECT_EQ(old.back(), HealthState::Offline);
  EXPECT_EQ(std::count(old.begin(), old.end(), HealthState::Offline), 1) << "OFFLINE once";
  EXPECT_EQ(m.h.worker().addresses(), (std::vector<std::uint16_t>{9}));
  EXPECT_EQ(m.h.sink.live_pmus(), (std::vector<std::uint16_t>{9}));
  ASSERT_NE(m.last_info(9), nullptr);
  EXPECT_EQ(m.last_info(9)->serial_number, 4001);
  ASSERT_NE(m.last_config(9), nullptr);
  EXPECT_EQ(raw_of(*m.last_config(9), Parameter::CanAddress), 9u);
  ASSERT_NE(m.h.sink.last_health(9), nullptr);
  EXPECT_EQ(m.h.sink.last_health(9)->state, HealthState::Online);
  // The evidence was the serial packet, asked of the new address.
  const auto sent = m.h.sent();
  EXPECT_TRUE(std::any_of(sent.begin(), sent.end(), [](const codec::PmuMessage& s) {
    return s.packet == codec::PacketId::Serial && s.request && s.address == 9;
  }));
  ASSERT_EQ(m.moved.size(), 1u);
  EXPECT_EQ(m.moved[0].to, 9);
}

TEST(AddressChange, APolledUnitThatStreamsNothingIsFoundByTheBroadcastSerialRequest) {
  auto unit = pmu(1);
  unit.parameters.set_raw(Parameter::PacketsStreamed, 0);  // silent unless asked
  Moves m({device(1, TelemetryMode::Polling, 1000ms)}, {unit});
  set_address_by_other_tool(m, 1, 9);
  m.h.run_for(30s);
  EXPECT_EQ(m.h.worker().addresses(), (std::vector<std::uint16_t>{9}));
  EXPECT_EQ(m.h.sink.live_pmus(), (std::vector<std::uint16_t>{9}));
  ASSERT_NE(m.h.sink.last_health(9), nullptr);
  EXPECT_EQ(m.h.sink.last_health(9)->state, HealthState::Online);
  const auto sent = m.h.sent();
  EXPECT_TRUE(std::any_of(sent.begin(), sent.end(), [](const codec::PmuMessage& s) {
    return s.packet == codec::PacketId::Serial && s.request && s.address == codec::kBroadcastAddress;
  }));
}

TEST(AddressChange, ADiscoveredUnitMovedByAnotherToolIsFollowedNotDiscoveredAgain) {
  Moves m({}, {pmu(1)}, true);
  ASSERT_EQ(m.h.worker().addresses(), (std::vector<std::uint16_t>{1}));
  set_address_by_other_tool(m, 1, 9);
  m.h.run_for(30s);  // past the next discovery broadcasts: their answer comes from 9
  EXPECT_EQ(m.h.worker().addresses(), (std::vector<std::uint16_t>{9}));
  EXPECT_EQ(m.h.sink.live_pmus(), (std::vector<std::uint16_t>{9}));
  ASSERT_EQ(m.moved.size(), 1u);
  EXPECT_TRUE(m.moved[0].config_line.empty()) << "discovered: no config line to change";
}

TEST(AddressChange, AConfiguredDeviceKnowsItsConfigLine) {
  Config cfg = parse_config("buses:\n  - interface: sim\n    devices:\n      - address: 1\n", "c.yaml");
  Moves m(cfg.buses[0].devices);
  ASSERT_EQ(m.move(1, 7).result, CommandResult::Completed);
  m.h.run_for(100ms);
  ASSERT_EQ(m.moved.size(), 1u);
  EXPECT_EQ(m.moved[0].config_line, "c.yaml:4");
}

TEST(AddressChange, AfterARestartTheRecordedSerialFollowsAUnitNeverHeardAtItsConfiguredAddress) {
  // The config says 1; the unit (serial 4001) answers at 9 since before the service started.
  auto unit = pmu(9);
  unit.serial_number = 4001;
  {
    Moves m({device(1)}, {unit});
    m.h.run_for(30s);
    EXPECT_EQ(m.h.worker().addresses(), (std::vector<std::uint16_t>{1})) << "no serial known: not followed";
  }
  Moves m({device(1)}, {unit});
  m.h.worker().session(1)->expect_serial(4001);
  m.h.run_for(30s);
  EXPECT_EQ(m.h.worker().addresses(), (std::vector<std::uint16_t>{9}));
  EXPECT_EQ(m.h.sink.live_pmus(), (std::vector<std::uint16_t>{9}));
  ASSERT_NE(m.last_info(9), nullptr);
  EXPECT_EQ(m.last_info(9)->serial_number, 4001);
  ASSERT_NE(m.h.sink.last_health(9), nullptr);
  EXPECT_EQ(m.h.sink.last_health(9)->state, HealthState::Online);
}

TEST(AddressChange, AUnitRecordedAsMovedThatAnswersAtItsConfiguredAddressEndsTheRecord) {
  Moves m({device(1)}, {pmu(1)});  // started (and read) before the expectation: read again
  m.h.worker().session(1)->expect_serial(4001);
  m.h.run_for(100ms);
  ASSERT_EQ(m.moved.size(), 1u);
  EXPECT_EQ(m.moved[0].from, 1);
  EXPECT_EQ(m.moved[0].to, 1);
  EXPECT_EQ(m.moved[0].first, 1);
  EXPECT_FALSE(m.h.worker().session(1)->expects_serial());
  EXPECT_TRUE(m.h.sink.gone.empty());
}

TEST(AddressChange, AnotherUnitAtANewAddressIsNotTakenForTheSilentOne) {
  // Unit 1 goes silent; a different unit (serial 4002) speaks at 2: not the same device.
  Moves m({device(1)}, {pmu(1), pmu(2)});
  m.h.pmus().with_model(1, [](sim::PmuModel& u) {
    sim::Faults off;
    off.silent = true;
    u.set_faults(off);
  });
  m.h.run_for(20s);
  EXPECT_TRUE(m.h.sink.gone.empty());
  EXPECT_EQ(m.h.worker().addresses(), (std::vector<std::uint16_t>{1}));
  ASSERT_NE(m.h.sink.last_health(1), nullptr);
  EXPECT_EQ(m.h.sink.last_health(1)->state, HealthState::Offline);
  // Asked once it went silent, then again only at the search's pace: not once a second.
  const auto sent = m.h.sent();
  const auto asked = std::count_if(sent.begin(), sent.end(), [](const codec::PmuMessage& s) {
    return s.packet == codec::PacketId::Serial && s.request && s.address == 2;
  });
  EXPECT_GE(asked, 1);
  EXPECT_LE(asked, 3);
}

}  // namespace
}  // namespace pmu::service::test
