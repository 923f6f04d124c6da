// Message signing: frames signed by one link verified by another with the same key; wrong
// key, altered bytes, replays and stale timestamps refused and counted; time injected.

#include <gtest/gtest.h>

#include "frame_builder.hpp"
#include "pmu/mavlink/messages.hpp"
#include "pmu/mavlink/parser.hpp"
#include "pmu/mavlink/signing.hpp"
#include "pmu/mavlink/writer.hpp"

namespace pmu::mavlink {
namespace {

using test::parse_all;

SecretKey key_of(std::uint8_t seed) {
  SecretKey key{};
  for (std::size_t i = 0; i < key.size(); ++i) key[i] = static_cast<std::uint8_t>(seed + 7 * i);
  return key;
}

// 2026-01-01T00:00:00Z as a signing timestamp.
constexpr std::uint64_t kNow = signing_timestamp(1767225600ULL * 1'000'000);

Frame parse_one(const std::vector<std::uint8_t>& bytes) {
  Parser parser;
  const auto results = parse_all(parser, bytes);
  EXPECT_EQ(results.size(), 1U);
  if (results.size() != 1 || !std::holds_alternative<Frame>(results[0])) return Frame{};
  return std::get<Frame>(results[0]);
}

// A frame signed by (sysid, compid) on `link` with timestamp `stamp`.
Frame signed_frame(std::uint8_t sysid, std::uint8_t compid, std::uint8_t link, std::uint64_t stamp,
                   const SecretKey& key = key_of(1)) {
  SigningLink signer(key, link);
  FrameWriter writer(sysid, compid);
  CommandLong c;
  c.command = mav_cmd::kDoSetRelay;
  c.param[0] = 2;
  c.param[1] = 1;
  return parse_one(writer.write_signed(c, signer, stamp));
}

TEST(MavlinkSigning, TimestampIsTenMicrosecondUnitsSince2015) {
  EXPECT_EQ(signing_timestamp(kSigningEpochUnixSeconds * 1'000'000), 0U);
  EXPECT_EQ(signing_timestamp(kSigningEpochUnixSeconds * 1'000'000 + 10), 1U);
  EXPECT_EQ(signing_timestamp((kSigningEpochUnixSeconds + 60) * 1'000'000), kSigningWindow);
  EXPECT_EQ(signing_timestamp(0), 0U);  // before 2015
}

TEST(MavlinkSigning, SignedFrameCarriesLinkTimestampAndFlag) {
  SigningLink signer(key_of(1), 3);
  FrameWriter writer(1, 180);
  const auto bytes = writer.write_signed(Heartbeat{}, signer, kNow);
  EXPECT_EQ(bytes[2], kIncompatSigned);
  const Frame f = parse_one(bytes);
  ASSERT_TRUE(f.signature.has_value());
  EXPECT_EQ(f.signature->link_id, 3);
  EXPECT_EQ(f.signature->timestamp, kNow);
  EXPECT_EQ(bytes.size(), kHeaderLength + f.payload_length + kChecksumLength + kSignatureLength);
  EXPECT_EQ(signer.counters().signed_out, 1U);
}

TEST(MavlinkSigning, OutgoingTimestampsStrictlyIncrease) {
  SigningLink signer(key_of(1), 0);
  EXPECT_EQ(signer.next_timestamp(kNow), kNow);
  EXPECT_EQ(signer.next_timestamp(kNow), kNow + 1);        // same clock reading: one more
  EXPECT_EQ(signer.next_timestamp(kNow - 500), kNow + 2);  // clock stepped back
  EXPECT_EQ(signer.next_timestamp(kNow + 100), kNow + 100);
}

TEST(MavlinkSigning, SameKeyAcceptsOtherKeyRefuses) {
  const Frame f = signed_frame(1, 180, 0, kNow);
  SigningLink good(key_of(1), 0);
  EXPECT_EQ(good.verify(f, kNow), Verdict::accepted);
  SigningLink bad(key_of(2), 0);
  EXPECT_EQ(bad.verify(f, kNow), Verdict::bad_signature);
  EXPECT_EQ(bad.counters().bad_signature, 1U);
  EXPECT_EQ(good.counters().accepted, 1U);
}

TEST(MavlinkSigning, EverySignedPartAlteredIsABadSignature) {
  const Frame original = signed_frame(1, 180, 0, kNow);
  const std::vector<std::pair<const char*, std::function<void(Frame&)>>> alterations = {
      {"sequence", [](Frame& f) { f.sequence ^= 1; }},
      {"sysid", [](Frame& f) { f.sysid ^= 1; }},
      {"compid", [](Frame& f) { f.compid ^= 1; }},
      {"msgid", [](Frame& f) { f.msgid ^= 0x100; }},
      {"compat flags", [](Frame& f) { f.compat_flags ^= 1; }},
      {"payload", [](Frame& f) { f.payload[0] ^= 1; }},
      {"checksum", [](Frame& f) { f.checksum ^= 1; }},
      {"link id", [](Frame& f) { f.signature->link_id ^= 1; }},
      {"timestamp", [](Frame& f) { f.signature->timestamp += 1; }},
      {"signature", [](Frame& f) { f.signature->value[5] ^= 1; }},
  };
  for (const auto& [name, alter] : alterations) {
    SCOPED_TRACE(name);
    Frame f = original;
    alter(f);
    SigningLink link(key_of(1), 0);
    EXPECT_EQ(link.verify(f, kNow), Verdict::bad_signature);
    // The forged frame moved nothing: the genuine one is still accepted.
    EXPECT_EQ(link.verify(original, kNow), Verdict::accepted);
  }
}

TEST(MavlinkSigning, UnsignedFrameIsReportedAndCounted) {
  FrameWriter writer(1, 180);
  const Frame f = parse_one(writer.write(Heartbeat{}));
  SigningLink link(key_of(1), 0);
  EXPECT_EQ(link.verify(f, kNow), Verdict::unsigned_frame);
  EXPECT_EQ(link.counters().unsigned_frames, 1U);
  EXPECT_EQ(link.counters().accepted, 0U);
}

struct ReplayStep {
  std::uint8_t sysid;
  std::uint8_t compid;
  std::uint8_t link;
  std::int64_t offset;  // the frame's timestamp relative to kNow
  Verdict expected;
};

TEST(MavlinkSigning, ReplayAndStaleRules) {
  const std::int64_t minute = static_cast<std::int64_t>(kSigningWindow);
  const std::vector<std::pair<const char*, std::vector<ReplayStep>>> cases = {
      {"newer timestamps accepted", {{1, 1, 0, 0, Verdict::accepted}, {1, 1, 0, 1, Verdict::accepted}}},
      {"same timestamp is a replay", {{1, 1, 0, 5, Verdict::accepted}, {1, 1, 0, 5, Verdict::replayed}}},
      {"older timestamp is a replay", {{1, 1, 0, 5, Verdict::accepted}, {1, 1, 0, 4, Verdict::replayed}}},
      {"streams are per system", {{1, 1, 0, 5, Verdict::accepted}, {2, 1, 0, 4, Verdict::accepted}}},
      {"streams are per component", {{1, 1, 0, 5, Verdict::accepted}, {1, 2, 0, 4, Verdict::accepted}}},
      {"streams are per link", {{1, 1, 0, 5, Verdict::accepted}, {1, 1, 1, 4, Verdict::accepted}}},
      {"new stream within a minute behind", {{1, 1, 0, -minute, Verdict::accepted}}},
      {"new stream more than a minute behind", {{1, 1, 0, -minute - 1, Verdict::stale}}},
      {"ahead of the clock is accepted", {{1, 1, 0, 10 * minute, Verdict::accepted}}},
      // The newest accepted frame moves the link's timestamp: another stream a minute behind
      // that is stale even though the clock has not moved.
      {"link timestamp follows accepted frames",
       {{1, 1, 0, 2 * minute, Verdict::accepted}, {2, 1, 0, minute - 1, Verdict::stale}}},
  };
  for (const auto& [name, steps] : cases) {
    SCOPED_TRACE(name);
    SigningLink link(key_of(1), 9);
    std::uint64_t replays = 0;
    std::uint64_t stale = 0;
    for (const auto& s : steps) {
      const Frame f = signed_frame(s.sysid, s.compid, s.link,
                                   static_cast<std::uint64_t>(static_cast<std::int64_t>(kNow) + s.offset));
      EXPECT_EQ(link.verify(f, kNow), s.expected) << to_string(s.expected);
      replays += s.expected == Verdict::replayed ? 1 : 0;
      stale += s.expected == Verdict::stale ? 1 : 0;
    }
    EXPECT_EQ(link.counters().replayed, replays);
    EXPECT_EQ(link.counters().stale, stale);
  }
}

TEST(MavlinkSigning, AcceptedFramesAdvanceTheOutgoingTimestamp) {
  SigningLink link(key_of(1), 0);
  const std::uint64_t ahead = kNow + 12345;
  ASSERT_EQ(link.verify(signed_frame(1, 1, 0, ahead), kNow), Verdict::accepted);
  EXPECT_EQ(link.timestamp(), ahead);
  EXPECT_EQ(link.next_timestamp(kNow), ahead + 1);
}

TEST(MavlinkSigning, StreamTableIsBounded) {
  SigningLink link(key_of(1), 0, 2);
  EXPECT_EQ(link.verify(signed_frame(1, 1, 0, kNow), kNow), Verdict::accepted);
  EXPECT_EQ(link.verify(signed_frame(2, 1, 0, kNow), kNow), Verdict::accepted);
  EXPECT_EQ(link.verify(signed_frame(3, 1, 0, kNow), kNow), Verdict::too_many_streams);
  EXPECT_EQ(link.verify(signed_frame(1, 1, 0, kNow + 1), kNow), Verdict::accepted);  // known streams go on
  EXPECT_EQ(link.counters().too_many_streams, 1U);
}

}  // namespace
}  // namespace pmu::mavlink
