// `pmuctl decode` line handling (interface.md section 3.2): one line in, one line out, the
// contract's JSON keys, errors with line numbers, firmware learned from 0x31 replies.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "pmuctl/decode/log_decoder.hpp"

namespace pmu::tools {
namespace {

using json = nlohmann::ordered_json;

json decode_one(LogDecoder& d, std::string_view line) {
  std::string out;
  d.decode_line(line, out);
  EXPECT_EQ(std::count(out.begin(), out.end(), '\n'), 1) << out;
  return json::parse(out);
}

TEST(LogDecoder, ContractShapeForATelemetryFrame) {
  LogDecoder d({true, std::nullopt});
  const json j = decode_one(d, "(1700000000.000000) can0 1E000001#7BA07B3CC8C83F");
  EXPECT_EQ(j["time"], 1700000000.0);
  EXPECT_EQ(j["interface"], "can0");
  EXPECT_EQ(j["id"], "1E000001");
  EXPECT_EQ(j["address"], 1);
  EXPECT_EQ(j["packet"], "voltages");
  EXPECT_EQ(j["values"]["avionics"], 12.3);
  EXPECT_EQ(j["values"]["output_28v"], 32.0);
  EXPECT_EQ(j["values"]["generator"], 25.2);
  EXPECT_FALSE(j.contains("request"));
  // Key order of the contract's example.
  std::vector<std::string> keys;
  for (auto it = j.begin(); it != j.end(); ++it) keys.push_back(it.key());
  EXPECT_EQ(keys, (std::vector<std::string>{"time", "interface", "id", "address", "packet", "values"}));
}

TEST(LogDecoder, ScreenFormatHasNullTime) {
  LogDecoder d({true, std::nullopt});
  const json j = decode_one(d, "  can0  1E100001   [1]  7B");
  EXPECT_TRUE(j["time"].is_null());
  EXPECT_EQ(j["packet"], "avionics_voltage");
  EXPECT_EQ(j["values"]["avionics_voltage"], 12.3);
}

// candump -td writes the time since the previous frame, -tz since its start: not dates.
// They are decoded as given and counted, so that pmuctl can say so.
TEST(LogDecoder, RelativeTimesAreCountedNotTakenForDates) {
  LogDecoder d({true, std::nullopt});
  const struct {
    const char* line;
    bool relative;
  } lines[] = {
      {"(000.000000) can0 1E000001#7BA07B3CC8C83F", true},
      {"(000.100250) can0 1E000001#7BA07B3CC8C83F", true},
      {"(99999999.999999) can0 1E000001#7BA07B3CC8C83F", true},
      {"(100000000.000000) can0 1E000001#7BA07B3CC8C83F", false},
      {"(1700000000.000000) can0 1E000001#7BA07B3CC8C83F", false},
      {"  can0  1E000001   [2]  FA 0A", false},
  };
  std::uint64_t expected = 0;
  for (const auto& l : lines) {
    SCOPED_TRACE(l.line);
    (void)decode_one(d, l.line);
    expected += l.relative ? 1 : 0;
    EXPECT_EQ(d.counts().relative_times, expected);
  }
  const json j = decode_one(d, "(000.100250) can0 1E000001#7BA07B3CC8C83F");
  EXPECT_DOUBLE_EQ(j["time"].get<double>(), 0.10025);
}

TEST(LogDecoder, ZeroLengthRequestHasNoValues) {
  LogDecoder d({true, std::nullopt});
  const json j = decode_one(d, "(1.5) can0 1E31FFFF#");
  EXPECT_EQ(j["packet"], "firmware");
  EXPECT_EQ(j["address"], 65535);
  EXPECT_EQ(j["request"], true);
  EXPECT_FALSE(j.contains("values"));
  EXPECT_EQ(j["time"], 1.5);
}

TEST(LogDecoder, NoSensorIsNull) {
  LogDecoder d({true, std::nullopt});
  const json j = decode_one(d, "can0 1E030001#19802A8031");
  EXPECT_EQ(j["values"]["internal"], 25.0);
  EXPECT_TRUE(j["values"]["battery_a"].is_null());
  EXPECT_EQ(j["values"]["battery_b"], 42.0);
  EXPECT_TRUE(j["values"]["generator"].is_null());
}

TEST(LogDecoder, BadLinesAreReportedWithTheirNumberAndDecodingGoesOn) {
  LogDecoder d({true, std::nullopt});
  EXPECT_EQ(decode_one(d, "(1.0) can0 1E000001#7BA07B3CC8C83F")["packet"], "voltages");
  json e = decode_one(d, "(1.0) can0 1E000001#FA0A");
  EXPECT_EQ(e["line"], 2);
  EXPECT_EQ(e["error"], "wrong length 2 for packet 0x00 voltages (expects 7, or 0 for a get)");
  e = decode_one(d, "garbage");
  EXPECT_EQ(e["line"], 3);
  EXPECT_EQ(e["error"], "missing frame");
  e = decode_one(d, "(1.0) can0 18FEF100#0102");
  EXPECT_EQ(e["line"], 4);
  EXPECT_NE(e["error"].get<std::string>().find("not a PMU frame"), std::string::npos);
  e = decode_one(d, "");
  EXPECT_EQ(e["line"], 5);
  EXPECT_EQ(decode_one(d, "can0 1E200001#03")["values"]["outputs"], 3);
  EXPECT_EQ(d.counts().lines, 6u);
  EXPECT_EQ(d.counts().frames, 2u);
  EXPECT_EQ(d.counts().errors, 4u);
}

TEST(LogDecoder, FirmwareLearnedFromTheLogSelectsBit6Meaning) {
  LogDecoder d({true, std::nullopt});
  json s = decode_one(d, "can0 1E040001#0000400000");
  EXPECT_EQ(s["bit6_meaning"], "soa_shutdown");
  EXPECT_TRUE(s["firmware"].is_null());
  EXPECT_EQ(s["values"]["soa_shutdown"], true);
  decode_one(d, "can0 1E310001#010F010607E7");  // firmware 1.15
  s = decode_one(d, "can0 1E040001#0000400000");
  EXPECT_EQ(s["bit6_meaning"], "start_button");
  EXPECT_EQ(s["firmware"], "1.15");
  EXPECT_EQ(s["values"]["start_button"], true);
  EXPECT_EQ(s["values"]["soa_shutdown"], false);
  // Another device is unaffected.
  EXPECT_EQ(decode_one(d, "can0 1E040002#0000400000")["bit6_meaning"], "soa_shutdown");
}

TEST(LogDecoder, FirmwareOptionIsTheDefaultForUnseenDevices) {
  LogDecoder d({true, codec::FirmwareVersion{1, 12}});
  json s = decode_one(d, "can0 1E040001#0000400000");
  EXPECT_EQ(s["bit6_meaning"], "start_button");
  EXPECT_EQ(s["firmware"], "1.12");
  json mr = decode_one(d, "can0 1E0F0001#1F");
  EXPECT_EQ(mr["note"], "measurement_request needs firmware 1.14 (device has 1.12)");
}

TEST(LogDecoder, CanOpenFramesAreDecodedToo) {
  LogDecoder d({true, std::nullopt});
  json b = decode_one(d, "can0 302#4305200101300000");
  EXPECT_EQ(b["packet"], "battery");
  EXPECT_EQ(b["values"]["voltage"], 12.289);
  json m = decode_one(d, "can0 4EE#4300000006E7000000");
  EXPECT_EQ(m["line"], 2);  // 9 bytes: refused
  m = decode_one(d, "can0 4EE#43000000061900000");
  EXPECT_TRUE(m.contains("error"));
  m = decode_one(d, "can0 4EE#4300000619000000");
  EXPECT_EQ(m["packet"], "mppt");
  EXPECT_EQ(m["device"], 1);
  EXPECT_EQ(m["values"]["temperature"], 25.0);
}

TEST(LogDecoder, TableFormIsOneLinePerInputToo) {
  LogDecoder d({false, std::nullopt});
  EXPECT_NE(d.header().find("PACKET"), std::string::npos);
  std::string out;
  d.decode_line("(1700000000.250000) can0 1E000001#7BA07B3CC8C83F", out);
  d.decode_line("bad", out);
  d.decode_line("can0 1E310001#", out);
  EXPECT_EQ(std::count(out.begin(), out.end(), '\n'), 3);
  EXPECT_NE(out.find("1700000000.250000  can0   1E000001     1  voltages"), std::string::npos) << out;
  EXPECT_NE(out.find("avionics=12.3 V"), std::string::npos);
  EXPECT_NE(out.find("line 2: error: missing frame"), std::string::npos) << out;
  EXPECT_NE(out.find("(request)"), std::string::npos);
}

}  // namespace
}  // namespace pmu::tools
