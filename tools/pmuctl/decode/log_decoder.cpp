#include "pmuctl/decode/log_decoder.hpp"

#include <cinttypes>
#include <cmath>
#include <cstdio>

#include "pmu/codec/candump.hpp"
#include "pmu/codec/canopen.hpp"
#include "pmu/codec/decode.hpp"
#include "pmuctl/decode/frame_fields.hpp"
#include "pmuctl/decode/json_line.hpp"

namespace pmu::tools {
namespace {

class JsonFields final : public FieldSink {
 public:
  explicit JsonFields(JsonLine& obj) : obj_(obj) {}
  void field(std::string_view name, const FieldValue& v, std::string_view) override {
    switch (v.kind) {
      case FieldValue::Kind::Number: obj_.number(name, v.number); break;  // NaN: null
      case FieldValue::Kind::Integer: obj_.integer(name, v.integer); break;
      case FieldValue::Kind::Boolean: obj_.boolean(name, v.boolean); break;
    }
  }

 private:
  JsonLine& obj_;
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

// "%08X" / "%03X" of the id, without printf: it is on every line.
struct HexId {
  char text[9];
  std::size_t size;
  std::string_view view() const { return {text, size}; }
  const char* c_str() const { return text; }  // text[size] is the NUL of the zeroed array
};

HexId hex_id(const codec::CanFrame& f) {
  static constexpr char digits[] = "0123456789ABCDEF";
  HexId h{};
  h.size = f.extended ? 8 : 3;
  std::uint32_t id = f.id;
  for (std::size_t i = h.size; i-- > 0; id >>= 4) h.text[i] = digits[id & 0xF];
  return h;
}

std::string time_text(const codec::CandumpLine& l) {
  if (!l.has_time) return "-";
  char buf[40];
  std::snprintf(buf, sizeof buf, "%" PRId64 ".%06u", l.seconds, l.microseconds);
  return buf;
}

void json_header(JsonLine& j, const codec::CandumpLine& l) {
  if (l.has_time)
    j.number("time", static_cast<double>(l.seconds) + l.microseconds / 1e6);
  else
    j.null("time");
  j.string("interface", l.interface);
  j.string("id", hex_id(l.frame).view());
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
      JsonLine(out).integer("line", static_cast<std::int64_t>(n)).string("error", reason).end();
    } else {
      out += "line " + std::to_string(n) + ": error: " + reason + '\n';
    }
  };

  const auto parsed = codec::parse_candump_line(line);
  if (!parsed) return report_error(std::string(parsed.error().reason));
  const codec::CandumpLine& l = *parsed;
  if (l.has_time && l.seconds < kEarliestAbsoluteTime) ++counts_.relative_times;

  if (codec::canopen::is_canopen_id(l.frame.id, l.frame.extended)) {
    const auto m = codec::canopen::decode(l.frame);
    if (!m) return report_error(m.error().describe());
    ++counts_.frames;
    const char* packet = m->source == codec::canopen::Source::Battery ? "battery" : "mppt";
    if (options_.json) {
      JsonLine j(out);
      json_header(j, l);
      j.string("packet", packet);
      if (m->source == codec::canopen::Source::Mppt) j.integer("device", m->device);
      j.integer("index", m->index).integer("subindex", m->subindex).integer("command_byte", m->command_byte);
      j.begin_object("values");
      JsonFields fields(j);
      visit_fields(*m, fields);
      j.end_object().end();
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
  if (const auto* info = std::get_if<codec::FirmwareInfo>(&m->payload)) learned_[m->address] = info->version();

  std::string note;
  if (m->unsupported_by_firmware)
    note = "measurement_request needs firmware 1.14 (device has " + codec::to_string(*fw) + ")";
  const auto* status = std::get_if<codec::Status>(&m->payload);
  const std::string_view packet = codec::packet_name(m->packet);

  if (options_.json) {
    JsonLine j(out);
    json_header(j, l);
    j.integer("address", m->address).string("packet", packet);
    if (m->request) {
      j.boolean("request", true);
    } else {
      j.begin_object("values");
      JsonFields fields(j);
      visit_fields(*m, fields);
      j.end_object();
    }
    if (status) {
      j.string("bit6_meaning", bit6_meaning_name(status->interpretation.bit6));
      if (fw)
        j.string("firmware", codec::to_string(*fw));
      else
        j.null("firmware");
    }
    if (!note.empty()) j.string("note", note);
    j.end();
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
