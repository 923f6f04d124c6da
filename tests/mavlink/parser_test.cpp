// The streaming parser: frames in any chunking, truncation restored, and each kind of bad
// input rejected and counted, with the frames behind it still found.

#include <gtest/gtest.h>

#include <random>

#include "frame_builder.hpp"
#include "pmu/mavlink/messages.hpp"
#include "pmu/mavlink/parser.hpp"
#include "pmu/mavlink/writer.hpp"

namespace pmu::mavlink {
namespace {

using test::concat;
using test::parse_all;
using test::raw_v1;
using test::raw_v2;

const Frame* frame_of(const ParseResult& r) { return std::get_if<Frame>(&r); }
const Rejection* rejection_of(const ParseResult& r) { return std::get_if<Rejection>(&r); }

std::vector<std::uint8_t> heartbeat_bytes(FrameWriter& writer, std::uint32_t custom_mode) {
  Heartbeat hb;
  hb.type = mav_type::kBattery;
  hb.system_status = mav_state::kActive;
  hb.custom_mode = custom_mode;
  return writer.write(hb);
}

// Three frames of different messages and lengths, as one stream.
std::vector<std::uint8_t> three_frames() {
  FrameWriter writer(1, 180);
  Statustext text;
  text.severity = mav_severity::kWarning;
  text.text = "battery A low";
  CommandAck ack;
  ack.command = mav_cmd::kDoEngineControl;
  ack.result = mav_result::kInProgress;
  ack.progress = 40;
  return concat({heartbeat_bytes(writer, 7), writer.write(text), writer.write(ack)});
}

void expect_three_frames(const std::vector<ParseResult>& results) {
  ASSERT_EQ(results.size(), 3U);
  const std::uint32_t ids[] = {msgid::kHeartbeat, msgid::kStatustext, msgid::kCommandAck};
  for (std::size_t i = 0; i < 3; ++i) {
    const Frame* f = frame_of(results[i]);
    ASSERT_NE(f, nullptr) << i;
    EXPECT_EQ(f->msgid, ids[i]);
    EXPECT_EQ(f->sequence, i);
    EXPECT_EQ(f->sysid, 1);
    EXPECT_EQ(f->compid, 180);
  }
  EXPECT_EQ(decode<Statustext>(std::get<Frame>(results[1]))->text, "battery A low");
  EXPECT_EQ(decode<CommandAck>(std::get<Frame>(results[2]))->progress, 40);
}

TEST(MavlinkParser, EveryChunkSizeGivesTheSameFrames) {
  const auto bytes = three_frames();
  for (std::size_t chunk = 1; chunk <= bytes.size(); ++chunk) {
    SCOPED_TRACE(chunk);
    Parser parser;
    expect_three_frames(parse_all(parser, bytes, chunk));
    EXPECT_EQ(parser.counters().frames, 3U);
    EXPECT_EQ(parser.counters().garbage_bytes, 0U);
    EXPECT_EQ(parser.buffered(), 0U);
  }
}

TEST(MavlinkParser, EverySplitPointInTwoPushes) {
  const auto bytes = three_frames();
  for (std::size_t split = 0; split <= bytes.size(); ++split) {
    SCOPED_TRACE(split);
    Parser parser;
    std::vector<ParseResult> results;
    parser.push(bytes.data(), split);
    while (auto r = parser.next()) results.push_back(*r);
    parser.push(bytes.data() + split, bytes.size() - split);
    while (auto r = parser.next()) results.push_back(*r);
    expect_three_frames(results);
  }
}

TEST(MavlinkParser, TrailingZerosTruncatedAndRestored) {
  FrameWriter writer(1, 180);
  CommandAck ack;
  ack.command = 0x014C;  // both bytes non-zero; result and every extension zero
  const auto bytes = writer.write(ack);
  EXPECT_EQ(bytes[1], 2U);  // payload length on the wire
  EXPECT_EQ(bytes.size(), kHeaderLength + 2 + kChecksumLength);

  Parser parser;
  const auto results = parse_all(parser, bytes);
  ASSERT_EQ(results.size(), 1U);
  const Frame& f = std::get<Frame>(results[0]);
  EXPECT_EQ(f.payload_length, 2U);
  for (std::size_t i = 2; i < f.payload.size(); ++i) ASSERT_EQ(f.payload[i], 0U) << i;
  const auto back = decode<CommandAck>(f);
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(back->command, 0x014C);
  EXPECT_EQ(back->result, 0);
  EXPECT_EQ(back->target_system, 0);
}

TEST(MavlinkParser, AllZeroPayloadKeepsItsFirstByte) {
  FrameWriter writer(1, 180);
  const auto bytes = writer.write(ParamRequestList{});
  EXPECT_EQ(bytes[1], 1U);
  Parser parser;
  const auto results = parse_all(parser, bytes);
  ASSERT_EQ(results.size(), 1U);
  EXPECT_NE(frame_of(results[0]), nullptr);
}

TEST(MavlinkParser, EmptyAndOverlongPayloadsOfAKnownMessageAreRead) {
  // An empty payload (a sender that truncates its first byte too) reads as all zero; a
  // payload longer than this side's definition (a newer sender's extensions) is delivered
  // and the fields this side knows are read from it.
  std::vector<std::uint8_t> longer{7, 0, 0, 0, mav_type::kGcs, 8, 0, mav_state::kActive, 3, 0xAA, 0xBB};
  const auto bytes = concat({raw_v2(msgid::kHeartbeat, {}, 50), raw_v2(msgid::kHeartbeat, longer, 50)});
  Parser parser;
  const auto results = parse_all(parser, bytes);
  ASSERT_EQ(results.size(), 2U);
  const auto empty = decode<Heartbeat>(std::get<Frame>(results[0]));
  EXPECT_EQ(empty->type, 0);
  EXPECT_EQ(empty->mavlink_version, 0);
  const auto full = decode<Heartbeat>(std::get<Frame>(results[1]));
  EXPECT_EQ(full->custom_mode, 7U);
  EXPECT_EQ(full->type, mav_type::kGcs);
  EXPECT_EQ(full->system_status, mav_state::kActive);
  EXPECT_EQ(std::get<Frame>(results[1]).payload_length, longer.size());
}

TEST(MavlinkParser, SequenceCountsPerWriterAndWraps) {
  FrameWriter writer(1, 180);
  Parser parser;
  for (unsigned i = 0; i < 300; ++i) {
    const auto results = parse_all(parser, heartbeat_bytes(writer, i));
    ASSERT_EQ(results.size(), 1U);
    ASSERT_EQ(std::get<Frame>(results[0]).sequence, i % 256);
  }
}

struct BadInputCase {
  const char* name;
  std::vector<std::uint8_t> bad;
  std::size_t rejections;  // Rejection results before the good frames
  RejectReason reason;
  ParserCounters counters;  // expected, but frames (3 + what the case adds)
  std::uint64_t extra_frames;
};

std::vector<std::uint8_t> bad_crc_frame() {
  FrameWriter writer(1, 180);
  auto bytes = heartbeat_bytes(writer, 0x01020304);
  bytes[kHeaderLength] ^= 0x10;  // a payload bit flipped in transit
  return bytes;
}

std::vector<BadInputCase> bad_inputs() {
  std::vector<BadInputCase> cases;
  cases.push_back(
      {"garbage without start marker", {0x00, 0x11, 0x22, 0x33}, 0, RejectReason::bad_crc, {0, 0, 0, 0, 0, 4}, 0});
  cases.push_back({"bad CRC", bad_crc_frame(), 1, RejectReason::bad_crc, {0, 1, 0, 0, 0, 20}, 0});
  // A start marker in garbage whose length byte claims a long frame: the good frames behind
  // it are found once the claimed frame fails its CRC.
  cases.push_back({"false start marker with a long length",
                   {0xFD, 30, 0, 0, 0, 1, 1, 0, 0, 0},
                   1,
                   RejectReason::bad_crc,
                   {0, 1, 0, 0, 0, 9},
                   0});
  // ATTITUDE (30): no CRC_EXTRA here, skipped whole, even with a start marker inside.
  cases.push_back({"unknown message id",
                   raw_v2(30, {0xFD, 0x09, 0, 0, 0, 1, 1, 0, 0, 0, 1, 2, 3}, 39),
                   1,
                   RejectReason::unknown_message,
                   {0, 0, 1, 0, 0, 0},
                   0});
  cases.push_back({"unknown incompat flag",
                   raw_v2(msgid::kHeartbeat, {1, 2, 3, 4, 5, 6, 7, 8, 9}, 50, 0x02),
                   1,
                   RejectReason::unsupported_incompat_flags,
                   {0, 0, 0, 1, 0, 20},
                   0});
  cases.push_back({"MAVLink 1 heartbeat",
                   raw_v1(0, {0, 0, 0, 0, 2, 3, 0x51, 4, 3}, 50),
                   1,
                   RejectReason::mavlink1,
                   {0, 0, 0, 0, 1, 0},
                   0});
  // A 0xFE that is no MAVLink 1 frame (its CRC fails): garbage, one byte at a time.
  cases.push_back(
      {"0xFE in garbage", {0xFE, 3, 0, 1, 1, 0, 1, 2, 3, 0xEE, 0xEE}, 0, RejectReason::bad_crc, {0, 0, 0, 0, 0, 11}, 0});
  return cases;
}

TEST(MavlinkParser, BadInputIsCountedAndTheFramesBehindItFound) {
  for (const auto& c : bad_inputs()) {
    for (std::size_t chunk : {std::size_t{1}, std::size_t{7}, std::size_t{1000}}) {
      SCOPED_TRACE(std::string(c.name) + ", chunk " + std::to_string(chunk));
      Parser parser;
      const auto results = parse_all(parser, concat({c.bad, three_frames()}), chunk);
      ASSERT_EQ(results.size(), c.rejections + 3);
      for (std::size_t i = 0; i < c.rejections; ++i) {
        const Rejection* r = rejection_of(results[i]);
        ASSERT_NE(r, nullptr);
        EXPECT_EQ(r->reason, c.reason);
      }
      expect_three_frames({results.begin() + static_cast<std::ptrdiff_t>(c.rejections), results.end()});
      const ParserCounters& n = parser.counters();
      EXPECT_EQ(n.frames, 3U + c.extra_frames);
      EXPECT_EQ(n.bad_crc, c.counters.bad_crc);
      EXPECT_EQ(n.unknown_message, c.counters.unknown_message);
      EXPECT_EQ(n.unsupported_incompat_flags, c.counters.unsupported_incompat_flags);
      EXPECT_EQ(n.mavlink1_frames, c.counters.mavlink1_frames);
      EXPECT_EQ(n.garbage_bytes, c.counters.garbage_bytes);
    }
  }
}

TEST(MavlinkParser, RejectionNamesTheFrame) {
  Parser parser;
  const auto results = parse_all(parser, raw_v2(30, {1, 2, 3}, 39, 0, 42, 200));
  ASSERT_EQ(results.size(), 1U);
  const Rejection& r = std::get<Rejection>(results[0]);
  EXPECT_EQ(r.reason, RejectReason::unknown_message);
  EXPECT_EQ(r.msgid, 30U);
  EXPECT_EQ(r.sysid, 42);
  EXPECT_EQ(r.compid, 200);
  EXPECT_STREQ(to_string(r.reason), "unknown message id");
}

TEST(MavlinkParser, WrongCrcExtraIsABadCrc) {
  // A sender whose HEARTBEAT definition differs (another CRC_EXTRA) is refused, not misread.
  Parser parser;
  const auto results = parse_all(parser, raw_v2(msgid::kHeartbeat, {1, 2, 3, 4, 5, 6, 7, 8, 9}, 51));
  ASSERT_EQ(results.size(), 1U);
  EXPECT_EQ(std::get<Rejection>(results[0]).reason, RejectReason::bad_crc);
}

TEST(MavlinkParser, IncompleteFrameWaitsForItsBytes) {
  const auto bytes = three_frames();
  Parser parser;
  parser.push(bytes.data(), 15);
  EXPECT_FALSE(parser.next().has_value());
  EXPECT_EQ(parser.buffered(), 15U);
  EXPECT_EQ(parser.counters().garbage_bytes, 0U);
}

// Random bytes in random chunks: whatever they hold, the parser keeps no more than one
// incomplete frame once it has given all it can, so a noisy link cannot grow its memory.
TEST(MavlinkParser, RandomBytesKeepAtMostOneIncompleteFrame) {
  std::mt19937 random(20261206);
  std::uniform_int_distribution<int> byte(0, 255);
  std::uniform_int_distribution<std::size_t> chunk(1, 600);
  Parser parser;
  std::size_t total = 0;
  while (total < 2'000'000) {
    std::vector<std::uint8_t> bytes(chunk(random));
    for (auto& b : bytes) {
      // One byte in eight a start marker, so many false frames begin (random message ids are
      // almost all unknown here, so most are skipped whole).
      const int r = byte(random);
      b = r < 16 ? kStartV2 : r < 32 ? kStartV1 : static_cast<std::uint8_t>(byte(random));
    }
    parser.push(bytes.data(), bytes.size());
    while (parser.next()) {
    }
    ASSERT_LT(parser.buffered(), kMaxFrameLength);
    total += bytes.size();
  }
  const ParserCounters& n = parser.counters();
  EXPECT_GT(n.unknown_message, 0U);
  EXPECT_GT(n.unsupported_incompat_flags, 0U);
}

// Good frames between runs of noise that holds no start marker: every frame is found, in
// any chunking, and the noise is counted to the byte.
TEST(MavlinkParser, FramesBetweenNoiseAllFound) {
  std::mt19937 random(7);
  std::uniform_int_distribution<int> noise_byte(0, 0xFC);
  std::uniform_int_distribution<std::size_t> noise_length(0, 40);
  FrameWriter writer(1, 180);
  std::vector<std::uint8_t> stream;
  std::uint64_t noise = 0;
  for (std::uint32_t i = 0; i < 500; ++i) {
    const std::size_t n = noise_length(random);
    for (std::size_t k = 0; k < n; ++k) stream.push_back(static_cast<std::uint8_t>(noise_byte(random)));
    noise += n;
    const auto frame = heartbeat_bytes(writer, i);
    stream.insert(stream.end(), frame.begin(), frame.end());
  }
  for (std::size_t chunk : {std::size_t{1}, std::size_t{13}, std::size_t{4096}}) {
    SCOPED_TRACE(chunk);
    Parser parser;
    const auto results = parse_all(parser, stream, chunk);
    ASSERT_EQ(results.size(), 500U);
    for (std::uint32_t i = 0; i < 500; ++i) {
      const Frame* f = frame_of(results[i]);
      ASSERT_NE(f, nullptr) << i;
      EXPECT_EQ(decode<Heartbeat>(*f)->custom_mode, i);
    }
    EXPECT_EQ(parser.counters().garbage_bytes, noise);
  }
}

}  // namespace
}  // namespace pmu::mavlink
