// `pmuctl decode` run as a user runs it (interface.md section 2), on the logs in tests/data:
// every packet of the spec decodes to the contract's names and values; one output line per
// input line; bad lines are reported by number and decoding goes on.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
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
    {"voltages", "avionics", 12.3},          // 0x7B = 123 -> 12.3 V
    {"currents", "output_28v", -12.5},       // 0x83 signed = -125
    {"battery_energy", "battery_a_mah", -100},  // 0xFF9C
    {"temperatures", "battery_a", nullptr},  // -128 = no sensor
    {"status", "generator_rpm", 4000},       // 0x0FA0
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

}  // namespace
