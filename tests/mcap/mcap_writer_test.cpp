// pmu::mcap (tools/mcap): records byte for byte against the MCAP spec
// (https://mcap.dev/spec, "Records" and "Serialization"), and whole files read back with a
// small reader written here from the spec.

#include <gtest/gtest.h>
#include <sys/mount.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <string>
#include <vector>

#include "pmu/mcap/crc32.hpp"
#include "pmu/mcap/records.hpp"
#include "pmu/mcap/sink.hpp"
#include "pmu/mcap/writer.hpp"

namespace {

using pmu::mcap::Bytes;

Bytes hex(const std::string& h) {
  Bytes b;
  for (std::size_t i = 0; i + 1 < h.size();) {
    if (h[i] == ' ') {
      ++i;
      continue;
    }
    b.push_back(static_cast<std::uint8_t>(std::stoul(h.substr(i, 2), nullptr, 16)));
    i += 2;
  }
  return b;
}

TEST(McapCrc32, KnownValues) {
  // The CRC-32 check value of "123456789" (IEEE 802.3) and its incremental form.
  const std::string s = "123456789";
  const auto* p = reinterpret_cast<const std::uint8_t*>(s.data());
  EXPECT_EQ(pmu::mcap::crc32(0, p, s.size()), 0xCBF43926u);
  EXPECT_EQ(pmu::mcap::crc32(pmu::mcap::crc32(0, p, 4), p + 4, 5), 0xCBF43926u);
  EXPECT_EQ(pmu::mcap::crc32(0, nullptr, 0), 0u);
}

struct RecordCase {
  const char* what;
  Bytes (*make)();
  const char* expected;  // opcode, u64 length, content (little-endian)
};

const RecordCase kRecords[] = {
    {"Header: profile \"\", library \"x\"",
     [] {
       Bytes b;
       pmu::mcap::append_header(b, "", "x");
       return b;
     },
     "01 0900000000000000 00000000 01000000 78"},
    {"Schema: id 1, name a, encoding omgidl, data \"s\"",
     [] {
       Bytes b;
       pmu::mcap::append_schema(b, {1, "a", "omgidl", "s"});
       return b;
     },
     "03 1600000000000000 0100 01000000 61 06000000 6f6d6769646c 01000000 73"},
    {"Channel: id 2, schema 1, topic t, cdr, no metadata",
     [] {
       Bytes b;
       pmu::mcap::append_channel(b, {2, 1, "t", "cdr", {}});
       return b;
     },
     "04 1400000000000000 0200 0100 01000000 74 03000000 636472 00000000"},
    {"Message: channel 2, sequence 3, log 4, publish 5, data AB",
     [] {
       Bytes b;
       const std::uint8_t d[] = {0xAB};
       pmu::mcap::append_message(b, 2, 3, 4, 5, d, 1);
       return b;
     },
     "05 1700000000000000 0200 03000000 0400000000000000 0500000000000000 ab"},
    {"MessageIndex: channel 1, (7, 0)",
     [] {
       Bytes b;
       pmu::mcap::append_message_index(b, 1, {{7, 0}});
       return b;
     },
     "07 1600000000000000 0100 10000000 0700000000000000 0000000000000000"},
    {"DataEnd: crc 0x01020304",
     [] {
       Bytes b;
       pmu::mcap::append_data_end(b, 0x01020304);
       return b;
     },
     "0f 0400000000000000 04030201"},
    {"SummaryOffset: group 0x03 at 16, 32 bytes",
     [] {
       Bytes b;
       pmu::mcap::append_summary_offset(b, 0x03, 16, 32);
       return b;
     },
     "0e 1100000000000000 03 1000000000000000 2000000000000000"},
    {"Footer without summary and CRC",
     [] {
       Bytes b;
       pmu::mcap::append_footer(b, 0, 0, 0, false);
       return b;
     },
     "02 1400000000000000 0000000000000000 0000000000000000 00000000"},
};

TEST(McapRecords, BytesAsTheSpecLaysThemOut) {
  for (const auto& c : kRecords) EXPECT_EQ(c.make(), hex(c.expected)) << c.what;
}

TEST(McapRecords, ChunkCarriesSizeAndCrcOfItsRecords) {
  Bytes records = hex("0102");
  Bytes b;
  pmu::mcap::append_chunk(b, 10, 20, records);
  const std::uint32_t crc = pmu::mcap::crc32(0, records.data(), records.size());
  Bytes expected = hex("06 2a00000000000000 0a00000000000000 1400000000000000 0200000000000000");
  for (int i = 0; i < 4; ++i) expected.push_back(static_cast<std::uint8_t>(crc >> (8 * i)));
  const Bytes rest = hex("00000000 0200000000000000 0102");
  expected.insert(expected.end(), rest.begin(), rest.end());
  EXPECT_EQ(b, expected);
}

// A reader of what Writer produces, from the spec alone.
struct Reader {
  const Bytes& b;
  std::size_t at = 0;
  template <class T>
  T get(std::size_t pos) const {
    std::uint64_t v = 0;
    for (std::size_t i = 0; i < sizeof(T); ++i) v |= std::uint64_t{b.at(pos + i)} << (8 * i);
    return static_cast<T>(v);
  }
  std::string str(std::size_t& pos) const {
    const auto n = get<std::uint32_t>(pos);
    std::string s(b.begin() + static_cast<std::ptrdiff_t>(pos + 4),
                  b.begin() + static_cast<std::ptrdiff_t>(pos + 4 + n));
    pos += 4 + n;
    return s;
  }
};

struct Message {
  std::uint16_t channel;
  std::uint32_t sequence;
  std::uint64_t log_time;
  std::string data;
};

struct Parsed {
  std::map<std::uint16_t, std::string> channel_topics;
  std::vector<Message> messages;
  std::vector<std::uint8_t> opcodes;  // top level
  bool footer = false;
  std::uint64_t summary_start = 0;
};

// Walks records from `from` to `to`, descending into chunks (checking their CRCs).
void walk(const Bytes& b, std::size_t from, std::size_t to, Parsed& p, bool top) {
  Reader r{b};
  std::size_t pos = from;
  while (pos + 9 <= to) {
    const std::uint8_t op = b[pos];
    const auto len = r.get<std::uint64_t>(pos + 1);
    ASSERT_LE(pos + 9 + len, to) << "record at " << pos << " runs past the end";
    std::size_t c = pos + 9;
    if (top) p.opcodes.push_back(op);
    if (op == pmu::mcap::kChannel) {
      const auto id = r.get<std::uint16_t>(c);
      std::size_t s = c + 4;
      p.channel_topics[id] = r.str(s);
    } else if (op == pmu::mcap::kMessage) {
      p.messages.push_back({r.get<std::uint16_t>(c), r.get<std::uint32_t>(c + 2), r.get<std::uint64_t>(c + 6),
                            std::string(b.begin() + static_cast<std::ptrdiff_t>(c + 22),
                                        b.begin() + static_cast<std::ptrdiff_t>(pos + 9 + len))});
    } else if (op == pmu::mcap::kChunk) {
      const auto size = r.get<std::uint64_t>(c + 16);
      const auto crc = r.get<std::uint32_t>(c + 24);
      std::size_t s = c + 28;
      EXPECT_EQ(r.str(s), "");
      const auto n = r.get<std::uint64_t>(s);
      EXPECT_EQ(n, size);
      EXPECT_EQ(pmu::mcap::crc32(0, b.data() + s + 8, n), crc);
      walk(b, s + 8, s + 8 + n, p, false);
    } else if (op == pmu::mcap::kFooter) {
      p.footer = true;
      p.summary_start = r.get<std::uint64_t>(c);
    }
    pos += 9 + len;
  }
}

Parsed parse(const Bytes& b) {
  Parsed p;
  EXPECT_GE(b.size(), 8u);
  EXPECT_EQ(std::memcmp(b.data(), pmu::mcap::kMagic, 8), 0);
  walk(b, 8,
       b.size() >= 16 && std::memcmp(b.data() + b.size() - 8, pmu::mcap::kMagic, 8) == 0 ? b.size() - 8 : b.size(), p,
       true);
  return p;
}

pmu::mcap::Writer make(pmu::mcap::Sink& s, std::size_t chunk = 1 << 20) {
  return pmu::mcap::Writer(s, {"", "test", chunk});
}

TEST(McapWriter, RoundTripWithSummaryAndFooter) {
  pmu::mcap::MemorySink sink;
  auto w = make(sink);
  ASSERT_TRUE(w.open());
  const auto schema = w.add_schema("pmu::v5::Voltages", "omgidl", "module pmu {};");
  const auto a = w.add_channel(schema, "pmu/voltages", "cdr");
  const auto b = w.add_channel(schema, "pmu/low_rate/voltages", "cdr");
  const std::uint8_t d1[] = {1, 2}, d2[] = {3};
  ASSERT_TRUE(w.write(a, 100, 100, d1, 2));
  ASSERT_TRUE(w.write(b, 50, 50, d2, 1));
  ASSERT_TRUE(w.write(a, 200, 200, d2, 1));
  ASSERT_TRUE(w.close());
  const Parsed p = parse(sink.bytes);
  ASSERT_EQ(p.messages.size(), 3u);
  EXPECT_EQ(p.channel_topics.at(a), "pmu/voltages");
  EXPECT_EQ(p.messages[2].sequence, 1u);  // per channel
  EXPECT_EQ(p.messages[1].log_time, 50u);
  EXPECT_EQ(p.messages[0].data, std::string("\x01\x02", 2));
  EXPECT_TRUE(p.footer);
  const std::vector<std::uint8_t> expected_ops = {
      pmu::mcap::kHeader,        pmu::mcap::kChunk,         pmu::mcap::kMessageIndex,  pmu::mcap::kMessageIndex,
      pmu::mcap::kDataEnd,       pmu::mcap::kSchema,        pmu::mcap::kChannel,       pmu::mcap::kChannel,
      pmu::mcap::kStatistics,    pmu::mcap::kChunkIndex,    pmu::mcap::kSummaryOffset, pmu::mcap::kSummaryOffset,
      pmu::mcap::kSummaryOffset, pmu::mcap::kSummaryOffset, pmu::mcap::kFooter};
  EXPECT_EQ(p.opcodes, expected_ops);
  // The summary starts with the Schema copy, right after DataEnd (13 bytes).
  EXPECT_EQ(sink.bytes.at(p.summary_start), pmu::mcap::kSchema);
  EXPECT_EQ(w.bytes_written(), sink.bytes.size());
}

TEST(McapWriter, FlushedChunksSurviveACrash) {
  pmu::mcap::MemorySink sink;
  auto w = make(sink);
  ASSERT_TRUE(w.open());
  const auto c = w.add_channel(w.add_schema("s", "omgidl", ""), "t", "cdr");
  const std::uint8_t d[] = {9};
  ASSERT_TRUE(w.write(c, 1, 1, d, 1));
  ASSERT_TRUE(w.flush());
  ASSERT_TRUE(w.write(c, 2, 2, d, 1));  // in memory only: lost in the "crash"
  const Parsed p = parse(sink.bytes);   // no close(): what a killed process leaves
  EXPECT_EQ(p.messages.size(), 1u);
  EXPECT_FALSE(p.footer);
}

TEST(McapWriter, SmallChunkSizeWritesManyChunks) {
  pmu::mcap::MemorySink sink;
  auto w = make(sink, 64);
  ASSERT_TRUE(w.open());
  const auto c = w.add_channel(w.add_schema("s", "omgidl", ""), "t", "cdr");
  const std::uint8_t d[40] = {};
  for (int i = 0; i < 10; ++i) ASSERT_TRUE(w.write(c, static_cast<std::uint64_t>(i), 0, d, sizeof d));
  ASSERT_TRUE(w.close());
  const Parsed p = parse(sink.bytes);
  EXPECT_EQ(p.messages.size(), 10u);
  EXPECT_GE(std::count(p.opcodes.begin(), p.opcodes.end(), pmu::mcap::kChunk), 9);
}

TEST(McapWriter, DiskFullCutsBackToTheLastChunkAndEndsTheFile) {
  pmu::mcap::MemorySink sink;
  auto w = make(sink, 64);
  ASSERT_TRUE(w.open());
  const auto c = w.add_channel(w.add_schema("s", "omgidl", ""), "t", "cdr");
  const std::uint8_t d[40] = {};
  ASSERT_TRUE(w.write(c, 1, 1, d, sizeof d));  // the first chunk (with schema and channel) is written
  const std::size_t good = sink.bytes.size();
  // The disk fills: the next chunk does not fit, nor would DataEnd + Footer + magic (50
  // bytes) in what is left, but the writer reserved room for them with the chunk before.
  sink.capacity = good + 30;
  EXPECT_FALSE(w.write(c, 2, 2, d, sizeof d));
  EXPECT_TRUE(w.failed());
  EXPECT_EQ(w.error(), ENOSPC);
  EXPECT_EQ(sink.bytes.size(), good);  // nothing half-written remains
  EXPECT_FALSE(w.write(c, 3, 3, d, sizeof d));
  EXPECT_FALSE(w.close());
  EXPECT_EQ(w.error(), ENOSPC);  // the first failure is the one reported
  EXPECT_EQ(sink.bytes.size(), good + 50);
  const Parsed p = parse(sink.bytes);
  EXPECT_TRUE(p.footer);
  EXPECT_EQ(p.messages.size(), 1u);
  EXPECT_EQ(p.summary_start, 0u);  // no summary: it did not fit

  // Room for the end records but not the summary: the same ending.
  pmu::mcap::MemorySink sink2;
  auto w2 = make(sink2, 64);
  ASSERT_TRUE(w2.open());
  const auto c2 = w2.add_channel(w2.add_schema("s", "omgidl", ""), "t", "cdr");
  ASSERT_TRUE(w2.write(c2, 1, 1, d, sizeof d));
  sink2.capacity = sink2.bytes.size() + 100;
  EXPECT_FALSE(w2.write(c2, 2, 2, d, 40));
  EXPECT_FALSE(w2.write(c2, 2, 2, d, 40));
  EXPECT_FALSE(w2.close());
  const Parsed p2 = parse(sink2.bytes);
  EXPECT_TRUE(p2.footer);
  EXPECT_EQ(p2.messages.size(), 1u);
}

TEST(McapWriter, ASummaryThatDoesNotFitLeavesTheShortEnding) {
  pmu::mcap::MemorySink sink;
  auto w = make(sink);
  ASSERT_TRUE(w.open());
  const auto c = w.add_channel(w.add_schema("s", "omgidl", std::string(500, 'x')), "t", "cdr");
  const std::uint8_t d[40] = {};
  ASSERT_TRUE(w.write(c, 1, 1, d, sizeof d));
  ASSERT_TRUE(w.flush());
  sink.capacity = sink.bytes.size() + 60;  // the summary repeats the 500-byte schema
  EXPECT_FALSE(w.close());
  EXPECT_EQ(w.error(), ENOSPC);
  const Parsed p = parse(sink.bytes);
  EXPECT_TRUE(p.footer);
  EXPECT_EQ(p.messages.size(), 1u);
}

// A stream (a pipe, a device) cannot be cut back after a write that failed half-way: the
// writer then writes nothing more, even once the stream would take bytes again, so the
// ending never follows half a chunk.
TEST(McapWriter, AStreamThatFailedHalfWayGetsNothingMore) {
  pmu::mcap::MemorySink sink;
  sink.stream = true;
  auto w = make(sink, 64);
  ASSERT_TRUE(w.open());
  const auto c = w.add_channel(w.add_schema("s", "omgidl", ""), "t", "cdr");
  const std::uint8_t d[40] = {};
  ASSERT_TRUE(w.write(c, 1, 1, d, sizeof d));
  const std::size_t complete = sink.bytes.size();
  sink.capacity = complete + 10;  // the next chunk breaks off after 10 bytes
  EXPECT_FALSE(w.write(c, 2, 2, d, sizeof d));
  ASSERT_EQ(sink.bytes.size(), complete + 10);
  sink.capacity = static_cast<std::size_t>(-1);
  EXPECT_FALSE(w.close());
  EXPECT_EQ(sink.bytes.size(), complete + 10);
  EXPECT_EQ(sink.reserved, 0u);
}

// The same on a real file system, where space is handed out in whole pages: whatever size
// the chunks have, the file that fills a small tmpfs ends with a footer. Without the
// reservation, a chunk that fails after the last page filled left no room for the ending.
TEST(McapFileSink, EveryFileThatFillsATmpfsEndsWithAFooter) {
  if (::geteuid() != 0) GTEST_SKIP() << "mounting a tmpfs needs root";
  char dir_template[] = "/tmp/mcap-full-XXXXXX";
  const char* dir = ::mkdtemp(dir_template);
  ASSERT_NE(dir, nullptr);
  if (::mount("tmpfs", dir, "tmpfs", 0, "size=16k") != 0) {
    const int e = errno;
    ::rmdir(dir);
    GTEST_SKIP() << "mount tmpfs: " << std::strerror(e);
  }
  const std::string path = std::string(dir) + "/full.mcap";
  std::vector<std::string> problems;
  for (std::size_t payload = 1; payload <= 400; payload += 7) {
    pmu::mcap::FileSink sink;
    ASSERT_EQ(sink.create(path), 0);
    auto w = make(sink, 1);  // every message its own chunk
    ASSERT_TRUE(w.open());
    const auto c = w.add_channel(w.add_schema("s", "omgidl", ""), "t", "cdr");
    const std::vector<std::uint8_t> d(payload, 0x5a);
    std::uint64_t written = 0;
    while (w.write(c, written + 1, written + 1, d.data(), d.size()) && written < 100000) ++written;
    EXPECT_EQ(w.error(), ENOSPC) << "payload " << payload;
    EXPECT_FALSE(w.close());
    sink.close();
    std::FILE* f = std::fopen(path.c_str(), "rb");
    ASSERT_NE(f, nullptr);
    Bytes bytes(32768);
    bytes.resize(std::fread(bytes.data(), 1, bytes.size(), f));
    std::fclose(f);
    const Parsed p = parse(bytes);
    if (!p.footer || p.messages.size() != written)
      problems.push_back("payload " + std::to_string(payload) + ": " + std::to_string(p.messages.size()) + " of " +
                         std::to_string(written) + " messages, footer " + (p.footer ? "yes" : "no"));
    ::unlink(path.c_str());
  }
  ::umount(dir);
  ::rmdir(dir);
  EXPECT_TRUE(problems.empty()) << problems.size() << " files, first: " << problems.front();
}

}  // namespace
