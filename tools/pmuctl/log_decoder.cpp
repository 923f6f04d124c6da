#include "pmuctl/log_decoder.hpp"

#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "pmu/codec/candump.hpp"
#include "pmu/codec/canopen.hpp"
#include "pmu/codec/decode.hpp"
#include "pmuctl/frame_fields.hpp"

namespace pmu::tools {
namespace {

using Json = nlohmann::ordered_json;

class JsonFields final : public FieldSink {
 public:
  explicit JsonFields(Json& obj) : obj_(obj) {}
  void field(std::string_view name, const FieldValue& v, std::string_view) override {
    Json& slot = obj_[std::string(name)];
    switch (v.kind) {
      case FieldValue::Kind::Number:
        if (std::isnan(v.number))
          slot = nullptr;
        else
          slot = v.number;
        break;
      case FieldValue::Kind::Integer: slot = v.integer; break;
      case FieldValue::Kind::Boolean: slot = v.boolean; break;
    }
  }

 private:
  Json& obj_;
};

class TableFields final : public FieldSink {
 public:
  explicit TableFields(std::string& out) : out_(out) {}
  void field(std::string_view name, const FieldValue& v, std::string_view unit) override {
    if (!first_) out_ += ' ';
    first_ = false;
    out_.append(name);
    out_ += '=';
    char buf[32];
    switch (v.kind) {
      case FieldValue::Kind::Number:
        if (std::isnan(v.number))
          out_ += "none";
        else {
          std::snprintf(buf, sizeof buf, "%g", v.number);
          out_ += buf;
        }
        break;
      case FieldValue::Kind::Integer:
        std::snprintf(buf, sizeof buf, "%" PRId64, v.integer);
        out_ += buf;
        break;
      case FieldValue::Kind::Boolean: out_ += v.boolean ? "yes" : "no"; break;
    }
    if (!unit.empty() && v.kind != FieldValue::Kind::Boolean) {
      out_ += ' ';
      out_.append(unit);
    }
  }

 private:
  std::string& out_;
  bool first_ = true;
};

std::string hex_id(const codec::CanFrame& f) {
  char buf[16];
  std::snprintf(buf, sizeof buf, f.extended ? "%08X" : "%03X", f.id);
  return buf;
}

std::string time_text(const codec::CandumpLine& l) {
  if (!l.has_time) return "-";
  char buf[40];
  std::snprintf(buf, sizeof buf, "%" PRId64 ".%06u", l.seconds, l.microseconds);
  return buf;
}

void json_header(Json& j, const codec::CandumpLine& l) {
  if (l.has_time)
    j["time"] = static_cast<double>(l.seconds) + l.microseconds / 1e6;
  else
    j["time"] = nullptr;
  j["interface"] = std::string(l.interface);
  j["id"] = hex_id(l.frame);
}

void append_json(std::string& out, const Json& j) {
  out += j.dump(-1, ' ', false, Json::error_handler_t::replace);
  out += '\n';
}

}  // namespace

LogDecoder::LogDecoder(DecodeOptions options) : options_(options) {}

std::optional<codec::FirmwareVersion> LogDecoder::firmware_of(std::uint16_t address) const {
  if (auto it = learned_.find(address); it != learned_.end()) return it->second;
  return options_.firmware;
}

std::string LogDecoder::header() const {
  if (options_.json) return {};
  char buf[128];
  std::snprintf(buf, sizeof buf, "%-18s %-6s %-8s %5s  %-23s %s\n", "TIME", "IFACE", "ID", "ADDR", "PACKET", "VALUES");
  return buf;
}

void LogDecoder::decode_line(std::string_view line, std::string& out) {
  const std::uint64_t n = ++counts_.lines;
  auto report_error = [&](const std::string& reason) {
    ++counts_.errors;
    if (options_.json) {
      Json j;
      j["line"] = n;
      j["error"] = reason;
      append_json(out, j);
    } else {
      out += "line " + std::to_string(n) + ": error: " + reason + '\n';
    }
  };

  const auto parsed = codec::parse_candump_line(line);
  if (!parsed) return report_error(std::string(parsed.error().reason));
  const codec::CandumpLine& l = *parsed;

  if (codec::canopen::is_canopen_id(l.frame.id, l.frame.extended)) {
    const auto m = codec::canopen::decode(l.frame);
    if (!m) return report_error(m.error().describe());
    ++counts_.frames;
    const char* packet = m->source == codec::canopen::Source::Battery ? "battery" : "mppt";
    if (options_.json) {
      Json j;
      json_header(j, l);
      j["packet"] = packet;
      if (m->source == codec::canopen::Source::Mppt) j["device"] = m->device;
      j["index"] = m->index;
      j["subindex"] = m->subindex;
      j["command_byte"] = m->command_byte;
      JsonFields fields(j["values"] = Json::object());
      visit_fields(*m, fields);
      append_json(out, j);
    } else {
      char buf[128];
      std::snprintf(buf, sizeof buf, "%-18s %-6.*s %-8s %5s  %-23s ", time_text(l).c_str(),
                    static_cast<int>(l.interface.size()), l.interface.data(), hex_id(l.frame).c_str(), "-", packet);
      out += buf;
      TableFields fields(out);
      visit_fields(*m, fields);
      out += '\n';
    }
    return;
  }

  const std::uint16_t address = codec::address_of_id(l.frame.id);
  const auto fw = firmware_of(address);
  const auto m = codec::decode(l.frame, fw);
  if (!m) return report_error(m.error().describe());
  ++counts_.frames;
  if (const auto* info = std::get_if<codec::FirmwareInfo>(&m->payload))
    learned_[m->address] = info->version();

  std::string note;
  if (m->unsupported_by_firmware)
    note = "measurement_request needs firmware 1.14 (device has " + codec::to_string(*fw) + ")";
  const auto* status = std::get_if<codec::Status>(&m->payload);
  const std::string_view packet = codec::packet_name(m->packet);

  if (options_.json) {
    Json j;
    json_header(j, l);
    j["address"] = m->address;
    j["packet"] = packet;
    if (m->request) {
      j["request"] = true;
    } else {
      JsonFields fields(j["values"] = Json::object());
      visit_fields(*m, fields);
    }
    if (status) {
      j["bit6_meaning"] = bit6_meaning_name(status->interpretation.bit6);
      j["firmware"] = fw ? Json(codec::to_string(*fw)) : Json(nullptr);
    }
    if (!note.empty()) j["note"] = note;
    append_json(out, j);
    return;
  }
  char buf[128];
  std::snprintf(buf, sizeof buf, "%-18s %-6.*s %-8s %5u  %-23.*s ", time_text(l).c_str(),
                static_cast<int>(l.interface.size()), l.interface.data(), hex_id(l.frame).c_str(), m->address,
                static_cast<int>(packet.size()), packet.data());
  out += buf;
  if (m->request) out += "(request)";
  TableFields fields(out);
  visit_fields(*m, fields);
  if (status) {
    out += " [bit 6 = ";
    out.append(bit6_meaning_name(status->interpretation.bit6));
    out += fw ? ", firmware " + codec::to_string(*fw) + "]" : std::string(", firmware unknown]");
  }
  if (!note.empty()) out += " [" + note + "]";
  out += '\n';
}

}  // namespace pmu::tools
