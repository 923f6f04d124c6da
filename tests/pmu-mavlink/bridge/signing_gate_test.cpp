// The signing gate (interface.md 12.6): with a key, what is addressed to this component
// reaches its handlers only signed with the key and fresh; each refusal counted by its kind;
// what is addressed to others or asks nothing goes on; the component's own frames signed.

#include "signing/signing_gate.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "pmu/mavlink/messages.hpp"
#include "pmu/mavlink/parser.hpp"
#include "pmu/mavlink/writer.hpp"

namespace pmu::mavlink_bridge {
// A named namespace: the unity builds put this file beside others of the target.
namespace signing_gate_test {

namespace nm = pmu::mavlink;

constexpr std::uint8_t kSystem = 1;
constexpr std::uint8_t kComponent = 180;
// 2026-01-01T00:00:00Z as a signing timestamp.
constexpr std::uint64_t kNow = nm::signing_timestamp(1767225600ULL * 1'000'000);

nm::SecretKey gate_key(std::uint8_t seed) {
  nm::SecretKey key{};
  for (std::size_t i = 0; i < key.size(); ++i) key[i] = static_cast<std::uint8_t>(seed + 11 * i);
  return key;
}

nm::Frame parsed(const std::vector<std::uint8_t>& bytes) {
  nm::Parser parser;
  parser.push(bytes.data(), bytes.size());
  auto r = parser.next();
  if (!r || !std::holds_alternative<nm::Frame>(*r)) {
    ADD_FAILURE() << "the frame does not parse";
    return nm::Frame{};
  }
  return std::get<nm::Frame>(*r);
}

nm::CommandLong set_message_interval_to(std::uint8_t system, std::uint8_t component) {
  nm::CommandLong c;
  c.target_system = system;
  c.target_component = component;
  c.command = nm::mav_cmd::kSetMessageInterval;
  c.param[0] = 147;
  c.param[1] = 1e6F;
  return c;
}

// How a ground station (system 255 unless told, component 190) signs: its own link, its own
// timestamps (each at least one more than the one before).
struct GroundStation {
  nm::SigningLink link;
  nm::FrameWriter writer;

  explicit GroundStation(const nm::SecretKey& key, std::uint8_t system = 255) : link(key, 2), writer(system, 190) {}

  template <class Message>
  nm::Frame signed_frame(const Message& m, std::uint64_t stamp) {
    return parsed(writer.write_signed(m, link, stamp));
  }
  template <class Message>
  nm::Frame unsigned_frame(const Message& m) {
    return parsed(writer.write(m));
  }
};

enum class Counted { none, accepted, unsigned_frame, bad_signature, replayed, stale };

std::uint64_t count_of(const nm::SigningCounters& c, Counted which) {
  switch (which) {
    case Counted::accepted: return c.accepted;
    case Counted::unsigned_frame: return c.unsigned_frames;
    case Counted::bad_signature: return c.bad_signature;
    case Counted::replayed: return c.replayed;
    case Counted::stale: return c.stale;
    case Counted::none: break;
  }
  return 0;
}

std::uint64_t total(const nm::SigningCounters& c) {
  return c.accepted + c.unsigned_frames + c.bad_signature + c.replayed + c.stale + c.too_many_streams;
}

TEST(SigningGate, AddressedFramesNeedTheKeyAndAFreshTimestamp) {
  const auto key = gate_key(1);
  GroundStation gcs(key);
  GroundStation stranger(gate_key(2));
  const auto to_us = set_message_interval_to(kSystem, kComponent);
  // Made in the order the ground station signs them, so each has the timestamp it names.
  const nm::Frame older = gcs.signed_frame(to_us, kNow - 5);
  const nm::Frame newest_first = gcs.signed_frame(to_us, kNow - 1);

  nm::ParamRequestList list_all;  // QGroundControl's list request: to every component
  list_all.target_system = kSystem;
  list_all.target_component = 0;
  nm::ParamSet set_on_autopilot;
  set_on_autopilot.target_system = kSystem;
  set_on_autopilot.target_component = 1;
  set_on_autopilot.param_id = "BATT_CAPACITY";
  nm::Statustext text;
  text.text = "hello";

  const struct {
    const char* what;
    nm::Frame frame;
    bool admitted;
    Counted counted;
  } cases[] = {
      {"signed with the key", gcs.signed_frame(to_us, kNow), true, Counted::accepted},
      {"unsigned", gcs.unsigned_frame(to_us), false, Counted::unsigned_frame},
      {"signed with another key", stranger.signed_frame(to_us, kNow + 1), false, Counted::bad_signature},
      {"an older frame of the stream, heard after a newer one", older, false, Counted::replayed},
      {"a newer frame of the stream", gcs.signed_frame(to_us, kNow + 7), true, Counted::accepted},
      {"a new stream more than a minute behind",
       GroundStation(key, 254).signed_frame(to_us, kNow - nm::kSigningWindow - 1), false, Counted::stale},
      {"broadcast to every component, unsigned", gcs.unsigned_frame(list_all), false, Counted::unsigned_frame},
      {"broadcast to every component, signed", gcs.signed_frame(list_all, kNow + 8), true, Counted::accepted},
      {"to system 0 (every system), unsigned", gcs.unsigned_frame(set_message_interval_to(0, kComponent)), false,
       Counted::unsigned_frame},
      {"to another component, unsigned", gcs.unsigned_frame(set_message_interval_to(kSystem, 1)), true, Counted::none},
      {"to another system, unsigned", gcs.unsigned_frame(set_message_interval_to(2, 0)), true, Counted::none},
      {"a parameter write for the autopilot, unsigned", gcs.unsigned_frame(set_on_autopilot), true, Counted::none},
      {"a STATUSTEXT (asks nothing), unsigned", gcs.unsigned_frame(text), true, Counted::none},
  };
  SigningGate gate(key);
  ASSERT_TRUE(gate.admits(newest_first, kSystem, kComponent, kNow));
  for (const auto& c : cases) {
    const nm::SigningCounters before = *gate.counters();
    EXPECT_EQ(gate.admits(c.frame, kSystem, kComponent, kNow), c.admitted) << c.what;
    const nm::SigningCounters& after = *gate.counters();
    if (c.counted == Counted::none) {
      EXPECT_EQ(total(after), total(before)) << c.what << ": not judged, not counted";
    } else {
      EXPECT_EQ(count_of(after, c.counted), count_of(before, c.counted) + 1) << c.what;
      EXPECT_EQ(total(after), total(before) + 1) << c.what << ": counted once, as one kind";
    }
  }
}

TEST(SigningGate, TheSameSignedBytesTwiceAreAReplay) {
  const auto key = gate_key(1);
  GroundStation gcs(key);
  const nm::Frame frame = gcs.signed_frame(set_message_interval_to(kSystem, kComponent), kNow);
  SigningGate gate(key);
  EXPECT_TRUE(gate.admits(frame, kSystem, kComponent, kNow));
  EXPECT_FALSE(gate.admits(frame, kSystem, kComponent, kNow + 100));
  EXPECT_EQ(gate.counters()->replayed, 1U);
}

TEST(SigningGate, WithoutAKeyEverythingGoesOnAndNothingIsSigned) {
  GroundStation gcs(gate_key(1));
  SigningGate gate;
  EXPECT_FALSE(gate.enabled());
  EXPECT_EQ(gate.outgoing(), nullptr);
  EXPECT_EQ(gate.counters(), nullptr);
  EXPECT_TRUE(gate.admits(gcs.unsigned_frame(set_message_interval_to(kSystem, kComponent)), kSystem, kComponent, kNow));
  EXPECT_TRUE(gate.authentic(gcs.unsigned_frame(nm::Heartbeat{}), kNow));
}

TEST(SigningGate, TheAutopilotHeartbeatIsAuthenticOnlySigned) {
  // A HEARTBEAT asks nothing, so it goes on; the system id is learned from it only when it
  // is authentic, or anyone in radio range could move the component to another system.
  const auto key = gate_key(1);
  nm::Heartbeat hb;
  hb.autopilot = 3;  // MAV_AUTOPILOT_ARDUPILOTMEGA
  nm::SigningLink autopilot_link(key, 0);
  nm::FrameWriter autopilot(7, 1);
  nm::FrameWriter forger(9, 1);
  SigningGate gate(key);

  const nm::Frame forged = parsed(forger.write(hb));
  EXPECT_TRUE(gate.admits(forged, kSystem, kComponent, kNow)) << "goes on: it asks nothing";
  EXPECT_FALSE(gate.authentic(forged, kNow));
  EXPECT_EQ(gate.counters()->unsigned_frames, 1U);
  EXPECT_TRUE(gate.authentic(parsed(autopilot.write_signed(hb, autopilot_link, kNow)), kNow));
}

TEST(SigningGate, OwnFramesAreSignedWithStrictlyIncreasingTimestamps) {
  const auto key = gate_key(1);
  SigningGate gate(key);
  ASSERT_NE(gate.outgoing(), nullptr);
  nm::FrameWriter writer(kSystem, kComponent);
  nm::Payload payload{};
  nm::Heartbeat{}.pack(payload);
  // The receiving side: a ground station's link with the same key.
  nm::SigningLink receiver(key, 5);
  std::uint64_t last = 0;
  // The clock stands still and then goes back: the timestamps still increase.
  for (const std::uint64_t now : {kNow, kNow, kNow - 1000}) {
    const nm::Frame f = parsed(writer.encode(nm::msgid::kHeartbeat, payload, gate.outgoing(), now));
    ASSERT_TRUE(f.signature);
    EXPECT_EQ(f.signature->link_id, SigningGate::kLinkId);
    EXPECT_GT(f.signature->timestamp, last);
    last = f.signature->timestamp;
    EXPECT_EQ(receiver.verify(f, kNow), nm::Verdict::accepted);
  }
  EXPECT_EQ(gate.counters()->signed_out, 3U);
}

TEST(SigningGate, MessagesOfAnUnclassedKindCountAsAddressed) {
  nm::Frame f;
  f.msgid = 12345;  // not in frame_target's list nor among the messages that ask nothing
  EXPECT_TRUE(addressed_to(f, kSystem, kComponent));
  f.msgid = nm::msgid::kBatteryStatus;
  EXPECT_FALSE(addressed_to(f, kSystem, kComponent));
}

}  // namespace signing_gate_test
}  // namespace pmu::mavlink_bridge
