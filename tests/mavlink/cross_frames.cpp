// The C++ side of the node-mavlink cross-check (cross_check.sh).
//   mavlink_cross_frames write KEYHEX        frames of every message pmu::mavlink writes,
//                                            unsigned and signed, one JSON line each, on stdout
//   mavlink_cross_frames read KEYHEX FILE    node-mavlink's frames (cross_check.mjs encode):
//                                            parsed, signatures verified, fields compared
// A line: {"hex", "msgid", "sysid", "compid", "seq", "payload_length", "crc", "crc_extra",
// "max_length", "signed", "link_id", "timestamp", "fields": {XML field name: value}}; a float
// NaN is "NaN", a uint64 a decimal string. Exit status: 0 agree, 1 a difference (each on
// stderr), 2 bad usage or input.

#include <cmath>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "pmu/mavlink/messages.hpp"
#include "pmu/mavlink/parser.hpp"
#include "pmu/mavlink/signing.hpp"
#include "pmu/mavlink/writer.hpp"

namespace {

using namespace pmu::mavlink;
using nlohmann::json;

json f32(float v) { return std::isnan(v) ? json("NaN") : json(static_cast<double>(v)); }

json fields(const Heartbeat& m) {
  return {{"type", m.type},
          {"autopilot", m.autopilot},
          {"base_mode", m.base_mode},
          {"custom_mode", m.custom_mode},
          {"system_status", m.system_status},
          {"mavlink_version", m.mavlink_version}};
}
json fields(const ParamRequestRead& m) {
  return {{"target_system", m.target_system},
          {"target_component", m.target_component},
          {"param_id", m.param_id.substr(0, 16)},
          {"param_index", m.param_index}};
}
json fields(const ParamRequestList& m) {
  return {{"target_system", m.target_system}, {"target_component", m.target_component}};
}
json fields(const ParamValue& m) {
  return {{"param_id", m.param_id.substr(0, 16)},
          {"param_value", f32(m.param_value)},
          {"param_type", m.param_type},
          {"param_count", m.param_count},
          {"param_index", m.param_index}};
}
json fields(const ParamSet& m) {
  return {{"target_system", m.target_system},
          {"target_component", m.target_component},
          {"param_id", m.param_id.substr(0, 16)},
          {"param_value", f32(m.param_value)},
          {"param_type", m.param_type}};
}
json fields(const CommandLong& m) {
  json j = {{"target_system", m.target_system},
            {"target_component", m.target_component},
            {"command", m.command},
            {"confirmation", m.confirmation}};
  for (std::size_t i = 0; i < m.param.size(); ++i) j["param" + std::to_string(i + 1)] = f32(m.param[i]);
  return j;
}
json fields(const CommandAck& m) {
  return {{"command", m.command},
          {"result", m.result},
          {"progress", m.progress},
          {"result_param2", m.result_param2},
          {"target_system", m.target_system},
          {"target_component", m.target_component}};
}
json fields(const BatteryStatus& m) {
  return {{"id", m.id},
          {"battery_function", m.battery_function},
          {"type", m.type},
          {"temperature", m.temperature},
          {"voltages", m.voltages},
          {"current_battery", m.current_battery},
          {"current_consumed", m.current_consumed},
          {"energy_consumed", m.energy_consumed},
          {"battery_remaining", m.battery_remaining},
          {"time_remaining", m.time_remaining},
          {"charge_state", m.charge_state},
          {"voltages_ext", m.voltages_ext},
          {"mode", m.mode},
          {"fault_bitmask", m.fault_bitmask}};
}
json fields(const Statustext& m) {
  return {{"severity", m.severity},
          {"text", m.text.substr(0, Statustext::kTextLength)},
          {"id", m.id},
          {"chunk_seq", m.chunk_seq}};
}
json fields(const GeneratorStatus& m) {
  return {{"status", std::to_string(m.status)},
          {"generator_speed", m.generator_speed},
          {"battery_current", f32(m.battery_current)},
          {"load_current", f32(m.load_current)},
          {"power_generated", f32(m.power_generated)},
          {"bus_voltage", f32(m.bus_voltage)},
          {"rectifier_temperature", m.rectifier_temperature},
          {"bat_current_setpoint", f32(m.bat_current_setpoint)},
          {"generator_temperature", m.generator_temperature},
          {"runtime", m.runtime},
          {"time_until_maintenance", m.time_until_maintenance}};
}
json fields(const RelayStatus& m) { return {{"time_boot_ms", m.time_boot_ms}, {"on", m.on}, {"present", m.present}}; }

std::string hex(const std::vector<std::uint8_t>& bytes) {
  static const char* digits = "0123456789abcdef";
  std::string out;
  for (auto b : bytes) {
    out += digits[b >> 4];
    out += digits[b & 0xF];
  }
  return out;
}

bool unhex(const std::string& text, std::vector<std::uint8_t>& out) {
  if (text.size() % 2 != 0) return false;
  out.clear();
  for (std::size_t i = 0; i < text.size(); i += 2) {
    try {
      out.push_back(static_cast<std::uint8_t>(std::stoul(text.substr(i, 2), nullptr, 16)));
    } catch (const std::exception&) {
      return false;
    }
  }
  return true;
}

// 2026-01-01T00:00:00Z as a signing timestamp: the writer's clock.
constexpr std::uint64_t kClock = signing_timestamp(1767225600ULL * 1'000'000);

struct Writer {
  FrameWriter writer{1, 180};
  SigningLink signing;
  explicit Writer(const SecretKey& key) : signing(key, 4) {}

  template <class M>
  void emit(const M& m) {
    for (bool sign : {false, true}) {
      const std::uint8_t seq = writer.next_sequence();
      const auto bytes = sign ? writer.write_signed(m, signing, kClock) : writer.write(m);
      const MessageInfo* info = find_message(M::kId);
      const std::size_t n = bytes.size();
      const std::size_t crc_at = sign ? n - kSignatureLength - 2 : n - 2;
      json line = {{"hex", hex(bytes)},
                   {"msgid", M::kId},
                   {"sysid", 1},
                   {"compid", 180},
                   {"seq", seq},
                   {"payload_length", bytes[1]},
                   {"crc", bytes[crc_at] | (bytes[crc_at + 1] << 8)},
                   {"crc_extra", info->crc_extra},
                   {"max_length", info->max_length},
                   {"signed", sign},
                   {"link_id", sign ? signing.link_id() : 0},
                   {"timestamp", sign ? signing.timestamp() : 0},
                   {"fields", fields(m)}};
      std::cout << line.dump() << "\n";
    }
  }
};

int write_frames(const SecretKey& key) {
  Writer w(key);
  Heartbeat hb;
  hb.type = mav_type::kBattery;
  hb.base_mode = 0x81;
  hb.custom_mode = 0xDEADBEEF;
  hb.system_status = mav_state::kActive;
  w.emit(hb);
  ParamRequestRead rr;
  rr.target_system = 255;
  rr.target_component = 190;
  rr.param_id = "PMU_BAT_A_CAP";
  rr.param_index = 12;
  w.emit(rr);
  w.emit(ParamRequestList{255, 190});
  ParamValue pv;
  pv.param_id = "ABCDEFGHIJKLMNOP";  // 16 chars: no terminator
  pv.param_value = 28.1F;
  pv.param_count = 150;
  pv.param_index = 149;
  w.emit(pv);
  ParamSet ps;
  ps.target_system = 1;
  ps.target_component = 180;
  ps.param_id = "PMU_OUT_28V_SET";
  ps.param_value = -0.5F;
  w.emit(ps);
  CommandLong cl;
  cl.target_system = 1;
  cl.target_component = 180;
  cl.command = mav_cmd::kPreflightRebootShutdown;
  cl.confirmation = 1;
  cl.param = {0.0F, 0.0F, 1.0F, 180.0F, NAN, 20190226.0F, -1e-3F};
  w.emit(cl);
  CommandAck ack;
  ack.command = mav_cmd::kDoEngineControl;
  ack.result = mav_result::kInProgress;
  ack.progress = 40;
  ack.result_param2 = -123456;
  ack.target_system = 255;
  ack.target_component = 190;
  w.emit(ack);
  CommandAck short_ack;  // extensions all zero: truncated to the base payload or less
  short_ack.command = mav_cmd::kRunPrearmChecks;
  short_ack.result = mav_result::kTemporarilyRejected;
  w.emit(short_ack);
  w.emit(BatteryStatus{});  // every "not provided" value
  BatteryStatus bs;
  bs.id = 10;
  bs.battery_function = mav_battery_function::kPropulsion;
  bs.type = mav_battery_type::kLion;
  bs.temperature = 2512;
  bs.voltages = {3601, 3602, 3603, 3604, 3605, 3606, 3607, UINT16_MAX, UINT16_MAX, UINT16_MAX};
  bs.current_battery = -1250;
  bs.current_consumed = 4321;
  bs.energy_consumed = 98765;
  bs.battery_remaining = 64;
  bs.time_remaining = 5400;
  bs.charge_state = mav_battery_charge_state::kLow;
  bs.voltages_ext = {3611, 1, 0, 0};
  bs.mode = mav_battery_mode::kAutoDischarging;
  bs.fault_bitmask = mav_battery_fault::kOverCurrent | mav_battery_fault::kIncompatibleCellsConfiguration;
  w.emit(bs);
  Statustext st;
  st.severity = mav_severity::kWarning;
  st.text = "PMU: battery B below 20 %, generator start inhibited";  // cut at 50
  st.id = 7;
  st.chunk_seq = 1;
  w.emit(st);
  w.emit(GeneratorStatus{});  // every "not provided" value
  GeneratorStatus gs;
  gs.status = mav_generator_status_flag::kGenerating | mav_generator_status_flag::kCharging |
              mav_generator_status_flag::kIdle | (std::uint64_t{1} << 62);
  gs.generator_speed = 5200;
  gs.battery_current = -12.5F;
  gs.load_current = 8.3F;
  gs.power_generated = 612.7F;
  gs.bus_voltage = 28.1F;
  gs.rectifier_temperature = 61;
  gs.bat_current_setpoint = -10.0F;
  gs.generator_temperature = -4;
  gs.runtime = 3601;
  gs.time_until_maintenance = -3600;
  w.emit(gs);
  w.emit(RelayStatus{987654321, 0x0005, 0x000F});
  return 0;
}

template <class M>
json decoded_fields(const Frame& frame) {
  return fields(*decode<M>(frame));
}

json fields_of(const Frame& frame, bool& known) {
  known = true;
  switch (frame.msgid) {
    case Heartbeat::kId: return decoded_fields<Heartbeat>(frame);
    case ParamRequestRead::kId: return decoded_fields<ParamRequestRead>(frame);
    case ParamRequestList::kId: return decoded_fields<ParamRequestList>(frame);
    case ParamValue::kId: return decoded_fields<ParamValue>(frame);
    case ParamSet::kId: return decoded_fields<ParamSet>(frame);
    case CommandLong::kId: return decoded_fields<CommandLong>(frame);
    case CommandAck::kId: return decoded_fields<CommandAck>(frame);
    case BatteryStatus::kId: return decoded_fields<BatteryStatus>(frame);
    case Statustext::kId: return decoded_fields<Statustext>(frame);
    case GeneratorStatus::kId: return decoded_fields<GeneratorStatus>(frame);
    case RelayStatus::kId: return decoded_fields<RelayStatus>(frame);
    default: known = false; return {};
  }
}

int read_frames(const SecretKey& key, const std::string& path) {
  std::ifstream in(path);
  if (!in) {
    std::cerr << path << ": cannot open\n";
    return 2;
  }
  std::vector<json> records;
  std::vector<std::uint8_t> stream;
  std::string text;
  for (int number = 1; std::getline(in, text); ++number) {
    if (text.empty()) continue;
    json line = json::parse(text, nullptr, false);
    std::vector<std::uint8_t> bytes;
    if (line.is_discarded() || !line.contains("hex") || !unhex(line["hex"].get<std::string>(), bytes)) {
      std::cerr << path << ":" << number << ": not a frame record\n";
      return 2;
    }
    stream.insert(stream.end(), bytes.begin(), bytes.end());
    records.push_back(std::move(line));
  }

  // One byte stream, pushed in chunks that split frames.
  Parser parser;
  std::vector<ParseResult> results;
  for (std::size_t at = 0; at < stream.size(); at += 5) {
    parser.push(stream.data() + at, std::min<std::size_t>(5, stream.size() - at));
    while (auto r = parser.next()) results.push_back(std::move(*r));
  }
  int differences = 0;
  auto differ = [&](std::size_t i, const std::string& what) {
    std::cerr << "record " << i + 1 << " (msgid " << records[i].value("msgid", 0) << "): " << what << "\n";
    ++differences;
  };
  if (results.size() != records.size()) {
    std::cerr << "parsed " << results.size() << " results from " << records.size() << " frames\n";
    return 1;
  }
  SigningLink link(key, 0);
  for (std::size_t i = 0; i < records.size(); ++i) {
    const json& rec = records[i];
    const Frame* frame = std::get_if<Frame>(&results[i]);
    if (frame == nullptr) {
      differ(i, std::string("rejected: ") + to_string(std::get<Rejection>(results[i]).reason));
      continue;
    }
    if (frame->msgid != rec["msgid"].get<std::uint32_t>()) differ(i, "msgid " + std::to_string(frame->msgid));
    if (frame->sysid != rec["sysid"].get<int>()) differ(i, "sysid " + std::to_string(frame->sysid));
    if (frame->compid != rec["compid"].get<int>()) differ(i, "compid " + std::to_string(frame->compid));
    if (frame->sequence != rec["seq"].get<int>()) differ(i, "seq " + std::to_string(frame->sequence));
    if (frame->payload_length != rec["payload_length"].get<int>()) {
      differ(i, "payload length " + std::to_string(frame->payload_length));
    }
    if (frame->checksum != rec["crc"].get<int>()) differ(i, "crc " + std::to_string(frame->checksum));
    const bool is_signed = rec["signed"].get<bool>();
    if (frame->signature.has_value() != is_signed) differ(i, "signature presence");
    if (is_signed && frame->signature) {
      if (frame->signature->link_id != rec["link_id"].get<int>()) differ(i, "link id");
      if (frame->signature->timestamp != rec["timestamp"].get<std::uint64_t>()) differ(i, "timestamp");
      const Verdict v = link.verify(*frame, frame->signature->timestamp);
      if (v != Verdict::accepted) differ(i, std::string("signature: ") + to_string(v));
    }
    bool known = false;
    const json mine = fields_of(*frame, known);
    if (!known) {
      differ(i, "no message of this id here");
      continue;
    }
    for (const auto& [name, expected] : rec["fields"].items()) {
      if (!mine.contains(name)) {
        differ(i, "field " + name + " unknown here");
      } else if (mine[name] != expected) {
        differ(i, "field " + name + ": " + mine[name].dump() + " here, " + expected.dump() + " from node-mavlink");
      }
    }
  }
  if (differences == 0) {
    std::cout << "read " << records.size() << " node-mavlink frames: ids, lengths, CRCs, signatures and fields agree\n";
  }
  return differences == 0 ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string usage = "usage: mavlink_cross_frames write KEYHEX | read KEYHEX FILE";
  if (argc < 3) {
    std::cerr << usage << "\n";
    return 2;
  }
  std::vector<std::uint8_t> key_bytes;
  SecretKey key{};
  if (!unhex(argv[2], key_bytes) || key_bytes.size() != key.size()) {
    std::cerr << "KEYHEX: 64 hex digits expected\n";
    return 2;
  }
  std::copy(key_bytes.begin(), key_bytes.end(), key.begin());
  const std::string mode = argv[1];
  if (mode == "write" && argc == 3) return write_frames(key);
  if (mode == "read" && argc == 4) return read_frames(key, argv[3]);
  std::cerr << usage << "\n";
  return 2;
}
