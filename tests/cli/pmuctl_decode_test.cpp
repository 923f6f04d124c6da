// `pmuctl decode` run as a user runs it (interface.md section 3.2), on the logs in tests/data:
// every packet of the spec decodes to the contract's names and values; one output line per
// input line; bad lines are reported by number and decoding goes on. `decode --mcap` onto
// each kind of path (interface.md section 9.1, "Where the file goes") leaves everything it did
// not create in place.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/un.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "support/process.hpp"

namespace {

using nlohmann::json;

struct CliRun {
  int status = -1;
  std::vector<std::string> lines;
};

CliRun run(const std::string& args) {
  const std::string cmd = std::string(PMUCTL_PATH) + " " + args + " 2>/dev/null";
  CliRun r;
  const auto run = pmu::test::run_capture(cmd);
  const std::string& cur = run.out;
  r.status = run.status;
  std::size_t start = 0;
  for (std::size_t i = 0; i < cur.size(); ++i)
    if (cur[i] == '\n') {
      r.lines.push_back(cur.substr(start, i - start));
      start = i + 1;
    }
  return r;
}

std::string data(const char* name) { return std::string(TEST_DATA_DIR) + "/" + name; }

struct Expect {
  const char* packet;
  const char* key;  // a value to check ("" = request, no values)
  json value;
};

// Line by line, what tests/data/every_packet.log holds (computed by hand from tables 2..24).
const Expect kEveryPacket[] = {
    {"voltages", "avionics", 12.3},             // 0x7B = 123 -> 12.3 V
    {"currents", "output_28v", -12.5},          // 0x83 signed = -125
    {"battery_energy", "battery_a_mah", -100},  // 0xFF9C
    {"temperatures", "battery_a", nullptr},     // -128 = no sensor
    {"status", "generator_rpm", 4000},          // 0x0FA0
    {"measurement_request", "measurements", 31},
    {"avionics_voltage", "avionics_voltage", 12.0},
    {"payload_voltage", "payload_voltage", 24.0},
    {"servo_voltage", "servo_voltage", 5.0},
    {"battery_voltage", "battery_voltage", 25.2},
    {"packet_period", "packet_period", 1.0},
    {"packets_streamed", "packets_streamed", 31},
    {"temperature_offset", "temperature_offset", 128},
    {"upper_temperature_limit", "upper_temperature_limit", 85},
    {"power_up_state", "power_up_state", 33},
    {"cranking_time", "cranking_time", 5.0},
    {"can_address", "can_address", 2},
    {"outputs", "outputs", 3},
    {"enable_outputs", "outputs", 2},
    {"disable_outputs", "outputs", 2},
    {"generation", "generation_enabled", true},
    {"engine_start", "", nullptr},
    {"engine_stop", "", nullptr},
    {"reset", "", nullptr},
    {"serial", "serial_number", 12345},
    {"firmware", "firmware_minor", 17},
    {"voltages", "", nullptr},
    {"can_address", "", nullptr},
};

TEST(PmuctlDecode, EveryPacketOfTheSpec) {
  const CliRun r = run("decode --json " + data("every_packet.log"));
  ASSERT_EQ(r.status, 0);
  ASSERT_EQ(r.lines.size(), std::size(kEveryPacket));
  for (std::size_t i = 0; i < r.lines.size(); ++i) {
    SCOPED_TRACE(r.lines[i]);
    const json j = json::parse(r.lines[i]);
    const Expect& e = kEveryPacket[i];
    EXPECT_EQ(j["packet"], e.packet);
    EXPECT_EQ(j["interface"], "can0");
    EXPECT_TRUE(j["time"].is_number());
    if (std::string(e.key).empty()) {
      EXPECT_EQ(j["request"], true);
      EXPECT_FALSE(j.contains("values"));
    } else {
      ASSERT_TRUE(j["values"].contains(e.key));
      EXPECT_EQ(j["values"][e.key], e.value);
    }
  }
  EXPECT_EQ(json::parse(r.lines[26])["address"], 65535);
}

TEST(PmuctlDecode, StandardInputAndScreenFormat) {
  const CliRun r = run("--json decode - < " + data("screen_format.log"));
  ASSERT_EQ(r.status, 0);
  ASSERT_EQ(r.lines.size(), 5u);
  EXPECT_EQ(json::parse(r.lines[0])["values"]["servo"], 6.0);
  const json status = json::parse(r.lines[1]);
  EXPECT_EQ(status["time"], 1700000000.5);
  EXPECT_EQ(status["values"]["payload_on"], true);
  EXPECT_EQ(json::parse(r.lines[2])["line"], 3);
  EXPECT_EQ(json::parse(r.lines[3])["packet"], "battery");
  EXPECT_EQ(json::parse(r.lines[4])["line"], 5);  // remote frame of an unknown id
}

TEST(PmuctlDecode, BadLinesAreNumberedAndDecodingGoesOn) {
  const CliRun r = run("decode --json " + data("bad_lines.log"));
  ASSERT_EQ(r.status, 0);
  ASSERT_EQ(r.lines.size(), 8u);
  const int bad[] = {2, 3, 4, 5, 6, 7};
  for (int n : bad) {
    const json j = json::parse(r.lines[static_cast<std::size_t>(n - 1)]);
    EXPECT_EQ(j["line"], n);
    EXPECT_FALSE(j["error"].get<std::string>().empty());
  }
  EXPECT_EQ(json::parse(r.lines[7])["packet"], "voltages");
}

TEST(PmuctlDecode, TableOutputHasAHeaderAndOneRowPerLine) {
  const CliRun r = run("decode " + data("every_packet.log"));
  ASSERT_EQ(r.status, 0);
  ASSERT_EQ(r.lines.size(), std::size(kEveryPacket) + 1);
  EXPECT_NE(r.lines[0].find("PACKET"), std::string::npos);
  EXPECT_NE(r.lines[1].find("avionics=12.3 V"), std::string::npos);
}

// The JSON lines are written without a document tree (json_line.hpp); each must be exactly
// the bytes nlohmann's dump gives for the same members, which is what it printed before and
// what scripts comparing decodings rely on.
TEST(PmuctlDecode, JsonLinesAreByteForByteNlohmannDumps) {
  for (const std::string& log : {data("every_packet.log"), data("bad_lines.log"), data("screen_format.log"),
                                 data("../../bench/testdata/all_packets.log")}) {
    const CliRun r = run("decode --json " + log);
    ASSERT_EQ(r.status, 0) << log;
    ASSERT_FALSE(r.lines.empty()) << log;
    for (std::size_t i = 0; i < r.lines.size(); ++i) {
      const auto parsed = nlohmann::ordered_json::parse(r.lines[i]);
      EXPECT_EQ(r.lines[i], parsed.dump(-1, ' ', false, nlohmann::ordered_json::error_handler_t::replace))
          << log << " output line " << i + 1;
    }
  }
}

TEST(PmuctlDecode, MissingFileAndBadFirmwareOptionFail) {
  EXPECT_NE(run("decode /nonexistent/file.log").status, 0);
  EXPECT_NE(run("decode --firmware 1.x " + data("every_packet.log")).status, 0);
  const CliRun old = run("decode --json --firmware 1.12 " + data("every_packet.log"));
  ASSERT_EQ(old.status, 0);
  EXPECT_EQ(json::parse(old.lines[4])["bit6_meaning"], "start_button");
}

// ---- decode --mcap onto each kind of path -------------------------------------------------

const std::string kMagic("\x89MCAP0\r\n", 8);

std::string slurp(const std::string& path) {
  std::string s;
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) return s;
  char buf[4096];
  ssize_t n;
  while ((n = ::read(fd, buf, sizeof buf)) > 0) s.append(buf, static_cast<std::size_t>(n));
  ::close(fd);
  return s;
}

bool is_mcap(const std::string& b) {
  return b.size() > 16 && b.compare(0, 8, kMagic) == 0 && b.compare(b.size() - 8, 8, kMagic) == 0;
}

struct Node {
  mode_t type = 0;
  ino_t inode = 0;
  bool operator==(const Node& o) const { return type == o.type && inode == o.inode; }
};

// Every name in `dir` with its kind and inode: what was removed, renamed over or added.
std::map<std::string, Node> names_in(const std::string& dir) {
  std::map<std::string, Node> out;
  const auto r = pmu::test::run_capture("ls -A '" + dir + "'");
  std::size_t start = 0;
  for (std::size_t i = 0; i < r.out.size(); ++i)
    if (r.out[i] == '\n') {
      const std::string name = r.out.substr(start, i - start);
      start = i + 1;
      struct stat st {};
      if (::lstat((dir + "/" + name).c_str(), &st) == 0)
        out[name] = {static_cast<mode_t>(st.st_mode & S_IFMT), st.st_ino};
    }
  return out;
}

struct McapTarget {
  const char* kind;
  bool root;                                         // mknod
  std::function<void(const std::string& dir)> make;  // makes dir/out (and what it points to)
  const char* path;
  int status;
  const char* mcap_in;  // the file that then holds the recording ("" none)
};

void mknod_or_fail(const std::string& path, mode_t mode, unsigned major, unsigned minor) {
  ASSERT_EQ(::mknod(path.c_str(), mode, makedev(major, minor)), 0) << path << ": " << std::strerror(errno);
}

const McapTarget kTargets[] = {
    {"new file", false, [](const std::string&) {}, "out", 0, "out"},
    {"regular file", false, [](const std::string& d) { std::fclose(std::fopen((d + "/out").c_str(), "w")); }, "out", 0,
     "out"},
    {"symlink", false,
     [](const std::string& d) {
       std::fclose(std::fopen((d + "/target").c_str(), "w"));
       ASSERT_EQ(::symlink("target", (d + "/out").c_str()), 0);
     },
     "out", 0, "target"},
    {"directory", false, [](const std::string& d) { ASSERT_EQ(::mkdir((d + "/out").c_str(), 0755), 0); }, "out", 2, ""},
    {"missing folder", false, [](const std::string&) {}, "no/out", 2, ""},
    {"FIFO without a reader", false, [](const std::string& d) { ASSERT_EQ(::mkfifo((d + "/out").c_str(), 0644), 0); },
     "out", 2, ""},
    {"socket", false,
     [](const std::string& d) {
       const int fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
       sockaddr_un a{};
       a.sun_family = AF_UNIX;
       std::snprintf(a.sun_path, sizeof a.sun_path, "%s/out", d.c_str());
       ASSERT_EQ(::bind(fd, reinterpret_cast<const sockaddr*>(&a), sizeof a), 0);
       ::close(fd);
     },
     "out", 2, ""},
    {"character device /dev/null", true, [](const std::string& d) { mknod_or_fail(d + "/out", S_IFCHR | 0666, 1, 3); },
     "out", 0, ""},
    {"character device /dev/full", true, [](const std::string& d) { mknod_or_fail(d + "/out", S_IFCHR | 0666, 1, 7); },
     "out", 1, ""},
    {"block device", true, [](const std::string& d) { mknod_or_fail(d + "/out", S_IFBLK | 0660, 7, 0); }, "out", 2, ""},
};

void decode_mcap_onto(const McapTarget& t) {
  SCOPED_TRACE(t.kind);
  char tmpl[] = "/tmp/pmuctl-decode-mcap-XXXXXX";
  const std::string dir = ::mkdtemp(tmpl);
  t.make(dir);
  const auto before = names_in(dir);
  const CliRun r = run("decode --mcap " + dir + "/" + t.path + " " + data("every_packet.log"));
  EXPECT_EQ(r.status, t.status);
  auto after = names_in(dir);
  if (*t.mcap_in) {
    EXPECT_TRUE(is_mcap(slurp(dir + "/" + t.mcap_in)));
    const auto was = before.find(t.mcap_in);  // the one name that may change: renamed onto
    if (was == before.end())
      after.erase(t.mcap_in);
    else
      after[t.mcap_in] = was->second;
  }
  EXPECT_EQ(after, before) << "names in " << dir << " changed";
  std::system(("rm -rf '" + dir + "'").c_str());
}

TEST(PmuctlDecodeMcap, NothingItDidNotCreateIsRemovedRenamedOverOrTruncated) {
  for (const McapTarget& t : kTargets)
    if (!t.root) decode_mcap_onto(t);
}

TEST(PmuctlDecodeMcap, DeviceNodesAreWrittenInPlaceOrRefused) {
  if (::geteuid() != 0) GTEST_SKIP() << "making device nodes (mknod) needs root";
  for (const McapTarget& t : kTargets)
    if (t.root) decode_mcap_onto(t);
}

// A FIFO with a reader gets the file in place (22 kB: within the pipe's buffer, so the reader
// may read it after pmuctl has exited); the FIFO stays.
TEST(PmuctlDecodeMcap, AFifoWithAReaderIsWrittenInPlace) {
  char tmpl[] = "/tmp/pmuctl-decode-mcap-XXXXXX";
  const std::string dir = ::mkdtemp(tmpl);
  const std::string fifo = dir + "/out";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0644), 0);
  const int reader = ::open(fifo.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  ASSERT_GE(reader, 0);
  const CliRun r = run("decode --mcap " + fifo + " " + data("every_packet.log"));
  EXPECT_EQ(r.status, 0);
  std::string got;
  char buf[4096];
  ssize_t n;
  while ((n = ::read(reader, buf, sizeof buf)) > 0) got.append(buf, static_cast<std::size_t>(n));
  ::close(reader);
  EXPECT_TRUE(is_mcap(got)) << got.size() << " bytes";
  struct stat st {};
  ASSERT_EQ(::lstat(fifo.c_str(), &st), 0);
  EXPECT_TRUE(S_ISFIFO(st.st_mode));
  EXPECT_EQ(names_in(dir).size(), 1u);
  std::system(("rm -rf '" + dir + "'").c_str());
}

// "-" is standard output, not a file named "-"; the size on stderr is what was written.
TEST(PmuctlDecodeMcap, DashIsStandardOutput) {
  char tmpl[] = "/tmp/pmuctl-decode-mcap-XXXXXX";
  const std::string dir = ::mkdtemp(tmpl);
  const auto r = pmu::test::run_capture("cd '" + dir + "' && " + PMUCTL_PATH + " decode --mcap - " +
                                        data("every_packet.log") + " 2>stderr.txt");
  EXPECT_EQ(r.status, 0);
  EXPECT_TRUE(is_mcap(r.out));
  EXPECT_NE(slurp(dir + "/stderr.txt").find("written to standard output (" + std::to_string(r.out.size()) + " bytes)"),
            std::string::npos)
      << slurp(dir + "/stderr.txt");
  EXPECT_EQ(names_in(dir).size(), 1u) << "only stderr.txt";
  std::system(("rm -rf '" + dir + "'").c_str());
}

}  // namespace
