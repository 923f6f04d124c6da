#include "pmu/config/config.hpp"

#include <sys/stat.h>
#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/yaml.h>

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <initializer_list>
#include <map>
#include <memory>
#include <set>
#include <sstream>
#include <string_view>
#include <utility>

#include "pmu/codec/decimal_text.hpp"
#include "pmu/codec/firmware.hpp"
#include "pmu/codec/messages.hpp"
#include "pmu/codec/telemetry.hpp"
#include "pmu/dds_settings/quoted.hpp"
#include "pmu/dds_settings/statistics_settings.hpp"
#include "pmu/dds_settings/vehicle.hpp"
#include "pmu/files/bounded_file.hpp"
#include "pmu/version.hpp"
#include "alarm_settings.hpp"
#include "baseline_setting.hpp"

namespace pmu::service {
namespace {

using dds::quoted;

constexpr std::size_t kMaxBusName = 15;  // the IDL key is string<15>; IFNAMSIZ - 1 too

struct Ctx {
  std::string source;
  ConfigEnvironment env;

  [[noreturn]] void fail(const YAML::Node& at, const std::string& what) const {
    // yaml-cpp marks are 0-based; editors count from 1.
    const int line = at.IsDefined() && at.Mark().line >= 0 ? at.Mark().line + 1 : 1;
    throw ConfigError(source + ":" + std::to_string(line) + ": " + what);
  }

  void only_keys(const YAML::Node& map, const char* where, std::initializer_list<const char*> keys) const {
    if (!map.IsMap()) fail(map, std::string(where) + " must be a mapping of key: value");
    for (const auto& kv : map) {
      const auto key = kv.first.as<std::string>();
      if (std::none_of(keys.begin(), keys.end(), [&](const char* k) { return key == k; })) {
        std::string known;
        for (const char* k : keys) known += std::string(known.empty() ? "" : ", ") + k;
        fail(kv.first, "unknown key " + quoted(key) + " in " + where + " (known: " + known + ")");
      }
    }
  }

  template <class T>
  T scalar(const YAML::Node& n, const char* name, const char* type) const {
    if (!n.IsScalar()) fail(n, std::string(name) + " must be " + type);
    try {
      return n.as<T>();
    } catch (const YAML::Exception&) {
      fail(n, std::string(name) + " must be " + type + ", not " + quoted(n.Scalar()) + "");
    }
  }

  double number(const YAML::Node& n, const char* name, double lo, double hi) const {
    const auto v = scalar<double>(n, name, "a number");
    if (!std::isfinite(v) || v < lo || v > hi) {
      std::ostringstream s;
      s << name << " " << n.Scalar() << " out of range " << lo << ".." << hi;
      fail(n, s.str());
    }
    return v;
  }

  long integer(const YAML::Node& n, const char* name, long lo, long hi) const {
    // yaml-cpp reads 010 as octal 8 and 0x10 as 16 (YAML 1.1), so an address written with
    // a leading zero would silently name another device: only plain decimal is taken.
    if (n.IsScalar() && !codec::is_plain_decimal(n.Scalar()))
      fail(n, std::string(name) +
                  " must be a decimal integer (digits, optionally after '-'; no leading 0, '+', "
                  "0x, 0o, exponent or fraction), not " +
                  quoted(n.Scalar()));
    const auto v = scalar<long>(n, name, "an integer");
    if (v < lo || v > hi)
      fail(n, std::string(name) + " " + n.Scalar() + " out of range " + std::to_string(lo) + ".." + std::to_string(hi));
    return v;
  }

  std::string line_of(const YAML::Node& n) const { return source + ":" + std::to_string(n.Mark().line + 1); }
};

std::uint8_t parse_groups(const Ctx& c, const YAML::Node& n) {
  if (!n.IsSequence()) c.fail(n, "packets must be a list, e.g. [voltages, status]");
  std::uint8_t mask = 0;
  for (const auto& item : n) {
    const auto name = c.scalar<std::string>(item, "packet", "a name");
    const auto bit = codec::bit_named(codec::kGroupNames, name);
    if (!bit)
      c.fail(item,
             "unknown packet " + quoted(name) + " (known: " + codec::names_of(codec::kGroupNames, 0xFF, ", ") + ")");
    mask = static_cast<std::uint8_t>(mask | *bit);
  }
  if (mask == 0) c.fail(n, "packets must name at least one packet");
  return mask;
}

std::chrono::milliseconds period_of(const Ctx& c, const YAML::Node& n, const char* name) {
  // A period is what PP can hold (0.1..25.5 s in 0.1 s steps); a poll period follows the
  // same rule.
  constexpr auto pp = codec::Parameter::PacketPeriod;
  const auto& spec = codec::spec_of(pp);
  const double s =
      c.number(n, name, codec::parameter_value(pp, spec.raw_min), codec::parameter_value(pp, spec.raw_max));
  const double raw = s * spec.divisor;
  if (std::fabs(raw - std::round(raw)) > 1e-6) {
    std::ostringstream m;
    m << name << " must be a multiple of " << codec::parameter_value(pp, 1) << " " << spec.unit;
    c.fail(n, m.str());
  }
  return codec::duration_of(pp, static_cast<std::uint32_t>(std::lround(raw)));
}

// ---- `sim:` (sim_settings.hpp, docs/interface.md section 4.4) ----

// A `sim:` mapping describes the built-in simulator's world; on a real bus nothing would
// read it, and a setting that silently does nothing is worse than a refusal.
void refuse_sim_on_real_bus(const Ctx& c, const YAML::Node& owner, const std::string& interface) {
  if (interface == "sim") return;
  for (const auto& kv : owner)
    if (kv.first.Scalar() == "sim")
      c.fail(kv.first, "sim: sets up the built-in simulator, but this bus has interface " + quoted(interface) +
                           ", not sim (remove sim:, or set interface: sim)");
}

bool sim_bool(const Ctx& c, const YAML::Node& n, const char* name) { return c.scalar<bool>(n, name, "true or false"); }

SimGarble parse_garble(const Ctx& c, const YAML::Node& n) {
  const auto g = c.scalar<std::string>(n, "garble", "none, wrong_length or unknown_subindex");
  if (g == "none") return SimGarble::None;
  if (g == "wrong_length") return SimGarble::WrongLength;
  if (g == "unknown_subindex") return SimGarble::UnknownSubindex;
  c.fail(n, "garble must be none, wrong_length or unknown_subindex, not " + quoted(g));
}

// What a field of the PMU's telemetry can carry (codec/telemetry.hpp): a plant value beyond
// it would be reported clamped, so the config and the frames would disagree.
template <class Packet>
double field_value(const Ctx& c, const YAML::Node& n, const char* name, std::string_view field) {
  for (const auto& f : codec::Telemetry<Packet>::fields)
    if (f.name == field) return c.number(n, name, f.min(), f.max());
  // Only if codec/telemetry.hpp lost the field: a build that cannot check this value says so.
  c.fail(n, std::string(name) + ": no telemetry field " + std::string(field));
}

// "1.14": MAJOR.MINOR as packet 0x31 carries them (a byte each). Read as the text written, so
// that 1.2 is minor 2 and 1.20 minor 20, whatever a YAML number would make of them.
codec::FirmwareVersion firmware_of(const Ctx& c, const YAML::Node& n, const char* name) {
  const auto text = c.scalar<std::string>(n, name, "a firmware version such as \"1.14\"");
  const auto dot = text.find('.');
  auto part = [&](const std::string& s) -> long {
    if (s.empty() || s.size() > 3 || s.find_first_not_of("0123456789") != std::string::npos) return -1;
    const long v = std::stol(s);
    return v <= 255 ? v : -1;
  };
  const long major = dot == std::string::npos ? -1 : part(text.substr(0, dot));
  const long minor = dot == std::string::npos ? -1 : part(text.substr(dot + 1));
  if (major < 0 || minor < 0)
    c.fail(n, std::string(name) + " " + quoted(text) + " is not MAJOR.MINOR (each 0..255, e.g. \"1.14\")");
  return {static_cast<std::uint8_t>(major), static_cast<std::uint8_t>(minor)};
}

PmuSimSettings parse_pmu_sim(const Ctx& c, const YAML::Node& n) {
  c.only_keys(n, "the PMU's sim",
              {"engine", "engine_starts_after", "internal_temperature", "battery_a_voltage", "battery_b_voltage",
               "starter_ready", "silent", "soa_shutdown", "payload_shed", "firmware", "serial", "ignores_set"});
  PmuSimSettings s;
  if (const auto v = n["engine"]) {
    const auto e = c.scalar<std::string>(v, "engine", "running or stopped");
    if (e != "running" && e != "stopped") c.fail(v, "engine must be running or stopped, not " + quoted(e));
    s.engine_running = e == "running";
  }
  if (const auto v = n["engine_starts_after"]) {
    if (v.IsScalar() && v.Scalar() == "never") {
      s.engine_never_starts = true;
    } else {
      if (!v.IsScalar() || !std::isfinite(v.as<double>(std::nan(""))))
        c.fail(v, "engine_starts_after must be seconds (0..3600) or never, not " +
                      quoted(v.IsScalar() ? v.Scalar() : std::string("a list or mapping")));
      s.engine_starts_after =
          std::chrono::milliseconds(std::lround(c.number(v, "engine_starts_after", 0, 3600) * 1000));
    }
  }
  if (const auto v = n["internal_temperature"])
    s.internal_temperature = field_value<codec::Temperatures>(c, v, "internal_temperature", "internal");
  if (const auto v = n["battery_a_voltage"])
    s.battery_a_voltage = field_value<codec::Voltages>(c, v, "battery_a_voltage", "battery_a");
  if (const auto v = n["battery_b_voltage"])
    s.battery_b_voltage = field_value<codec::Voltages>(c, v, "battery_b_voltage", "battery_b");
  if (const auto v = n["starter_ready"]) s.starter_ready = sim_bool(c, v, "starter_ready");
  if (const auto v = n["silent"]) s.silent = sim_bool(c, v, "silent");
  if (const auto v = n["soa_shutdown"]) s.soa_shutdown = sim_bool(c, v, "soa_shutdown");
  if (const auto v = n["payload_shed"]) s.payload_shed = sim_bool(c, v, "payload_shed");
  if (const auto v = n["firmware"]) {
    s.firmware = firmware_of(c, v, "firmware");
    // The simulator behaves as a documented firmware only; refused here, at check time,
    // rather than by the model when the service starts (interface.md 4.4).
    if (!codec::is_described(*s.firmware))
      c.fail(v, "firmware " + quoted(v.Scalar()) + ": the simulator is firmware " +
                    codec::to_string(codec::kOldestDescribedFirmware) + ".." +
                    codec::to_string(codec::kCurrentFirmware) + " (the versions the protocol documents describe)");
  }
  if (const auto v = n["serial"]) s.serial = static_cast<std::uint16_t>(c.integer(v, "serial", 0, 65535));
  if (const auto v = n["ignores_set"]) {
    const auto name = c.scalar<std::string>(v, "ignores_set", "a stored parameter's name");
    s.ignores_set = codec::parameter_from_name(name);
    if (!s.ignores_set) c.fail(v, "ignores_set: " + quoted(name) + " is not a stored parameter");
  }
  return s;
}

// A simulated pack has 1..15 cells: the most whose full voltage fits 0x302's 65.535 V
// (sim::BatterySimConfig::cells).
constexpr long kMaxSimCells = 15;
// A cell voltage a Li-ion cell can show, with room for an over-charged one.
constexpr double kMaxSimCellVoltage = 5.0;

BatterySimSettings parse_battery_sim(const Ctx& c, const YAML::Node& n) {
  c.only_keys(n, "the battery's sim", {"state_of_charge", "cells", "cell_voltages", "silent", "garble"});
  BatterySimSettings s;
  if (const auto v = n["state_of_charge"]) s.state_of_charge = c.number(v, "state_of_charge", 0, 100);
  if (const auto v = n["cells"]) s.cells = static_cast<int>(c.integer(v, "cells", 1, kMaxSimCells));
  if (const auto v = n["cell_voltages"]) {
    if (!v.IsSequence() || v.size() == 0 || v.size() > static_cast<std::size_t>(kMaxSimCells))
      c.fail(v, "cell_voltages must be a list of 1..15 voltages, cell 1 first, e.g. [3.9, 3.9, 3.7]");
    for (const auto& item : v) s.cell_voltages.push_back(c.number(item, "cell voltage", 0, kMaxSimCellVoltage));
    if (s.cells && static_cast<std::size_t>(*s.cells) != s.cell_voltages.size())
      c.fail(v, "cell_voltages has " + std::to_string(s.cell_voltages.size()) + " voltages but cells is " +
                    std::to_string(*s.cells) + " (give one per cell, or leave cells out)");
  }
  if (const auto v = n["silent"]) s.silent = sim_bool(c, v, "silent");
  if (const auto v = n["garble"]) s.garble = parse_garble(c, v);
  return s;
}

MpptSimSettings parse_mppt_sim(const Ctx& c, const YAML::Node& n) {
  c.only_keys(n, "the MPPT's sim", {"panels", "silent", "garble"});
  MpptSimSettings s;
  if (const auto v = n["panels"]) s.panels = static_cast<int>(c.integer(v, "panels", 0, 4));
  if (const auto v = n["silent"]) s.silent = sim_bool(c, v, "silent");
  if (const auto v = n["garble"]) s.garble = parse_garble(c, v);
  return s;
}

void parse_device_settings(const Ctx& c, const YAML::Node& n, DeviceConfig& d) {
  if (const auto m = n["mode"]) {
    const auto mode = c.scalar<std::string>(m, "mode", "streaming or polling");
    if (mode == "streaming")
      d.mode = TelemetryMode::Streaming;
    else if (mode == "polling")
      d.mode = TelemetryMode::Polling;
    else
      c.fail(m, "mode must be streaming or polling, not " + quoted(mode) + "");
  }
  if (const auto p = n["period"]) d.period = period_of(c, p, "period");
  if (const auto p = n["packets"]) d.groups = parse_groups(c, p);
  if (const auto p = n["configure_streaming"])
    d.configure_streaming = c.scalar<bool>(p, "configure_streaming", "true or false");
  // Table 6 carries the speed in 16 bits; a hold past the longest cranking time (25.5 s)
  // could never be met within one start.
  if (const auto p = n["engine_running_rpm"])
    d.engine.running_rpm = static_cast<std::uint16_t>(c.integer(p, "engine_running_rpm", 1, 65534));
  if (const auto p = n["engine_running_hold"])
    d.engine.running_hold = std::chrono::milliseconds(std::lround(c.number(p, "engine_running_hold", 0, 25.5) * 1000));
  if (const auto p = n["alarms"]) d.alarms = parse_alarm_settings(p, alarms::DeviceKind::Pmu, c.source);
  if (const auto p = n["min_firmware"]) d.min_firmware = firmware_of(c, p, "min_firmware");
}

DeviceConfig parse_device(const Ctx& c, const YAML::Node& n, BusConfig& b) {
  c.only_keys(n, "device",
              {"address", "mode", "period", "packets", "configure_streaming", "engine_running_rpm",
               "engine_running_hold", "min_firmware", "sim", "alarms", "baseline"});
  refuse_sim_on_real_bus(c, n, b.interface);
  DeviceConfig d;
  const auto a = n["address"];
  // 65535 is the broadcast address, never a device's (v1.9 section 4).
  if (!a) c.fail(n, "device needs an address (0.." + std::to_string(codec::kMaxDeviceAddress) + ")");
  d.address = static_cast<std::uint16_t>(c.integer(a, "address", 0, codec::kMaxDeviceAddress));
  d.source_line = c.line_of(a);
  parse_device_settings(c, n, d);
  if (const auto v = n["sim"]) b.sim.pmus[d.address] = parse_pmu_sim(c, v);
  // After min_firmware: the baseline's values must fit the firmware the unit has at least.
  if (const auto v = n["baseline"]) read_baseline(v, c.source, d);
  return d;
}

// Seconds between a battery's or MPPT's frames of one value. Their firmware sets it, not us,
// so any rate a CAN bus can carry is accepted.
std::chrono::milliseconds canopen_period(const Ctx& c, const YAML::Node& n) {
  return std::chrono::milliseconds(std::lround(c.number(n, "period", 0.01, 3600) * 1000));
}

// A battery's nameplate capacity. The top bound only catches a slip of units (mAh for Ah):
// no battery on a bus with a 250 W PMU holds 10,000 Ah.
double capacity_ah(const Ctx& c, const YAML::Node& n) {
  const double ah = c.number(n, "capacity_ah", 0, 10000);
  if (ah == 0) c.fail(n, "capacity_ah must be more than 0 Ah");
  return ah;
}

void parse_batteries(const Ctx& c, const YAML::Node& n, BusConfig& b) {
  if (!n.IsSequence()) c.fail(n, "batteries must be a list, e.g. [{node: 2, period: 1.0}]");
  std::set<std::uint8_t> seen;
  for (const auto& item : n) {
    c.only_keys(item, "battery", {"node", "period", "capacity_ah", "sim", "alarms"});
    refuse_sim_on_real_bus(c, item, b.interface);
    BatteryConfig bat;
    const auto node = item["node"];
    if (!node) c.fail(item, "battery needs a node (2: COB-IDs 0x202, 0x302, 0x402, 0x482)");
    // The document defines the BMS's frames for node 2 only; another node's would never be
    // decoded, and the battery would sit OFFLINE for a reason nobody could see.
    bat.node = static_cast<std::uint8_t>(c.integer(node, "node", 2, 2));
    if (const auto p = item["period"]) bat.period = canopen_period(c, p);
    if (const auto v = item["capacity_ah"]) bat.capacity_ah = capacity_ah(c, v);
    if (const auto v = item["sim"]) b.sim.batteries[bat.node] = parse_battery_sim(c, v);
    if (const auto p = item["alarms"]) bat.alarms = parse_alarm_settings(p, alarms::DeviceKind::Battery, c.source);
    if (!seen.insert(bat.node).second)
      c.fail(item, "battery node " + std::to_string(bat.node) + " appears twice on bus " + b.name);
    b.batteries.push_back(bat);
  }
}

void parse_mppts(const Ctx& c, const YAML::Node& n, BusConfig& b) {
  if (!n.IsSequence()) c.fail(n, "mppts must be a list, e.g. [{device: 0, period: 1.0}]");
  std::set<std::uint8_t> seen;
  for (const auto& item : n) {
    c.only_keys(item, "mppt", {"device", "period", "sim", "alarms"});
    refuse_sim_on_real_bus(c, item, b.interface);
    MpptConfig m;
    const auto device = item["device"];
    if (!device) c.fail(item, "mppt needs a device (0..7, set by the MPPT's resistors)");
    m.device = static_cast<std::uint8_t>(c.integer(device, "device", 0, 7));
    if (const auto p = item["period"]) m.period = canopen_period(c, p);
    if (const auto v = item["sim"]) b.sim.mppts[m.device] = parse_mppt_sim(c, v);
    if (const auto p = item["alarms"]) m.alarms = parse_alarm_settings(p, alarms::DeviceKind::Mppt, c.source);
    if (!seen.insert(m.device).second)
      c.fail(item, "mppt device " + std::to_string(m.device) + " appears twice on bus " + b.name);
    b.mppts.push_back(m);
  }
}

BusConfig parse_bus(const Ctx& c, const YAML::Node& n) {
  c.only_keys(
      n, "bus",
      {"name", "interface", "bitrate", "devices", "discover", "batteries", "mppts", "listen_canopen", "alarms"});
  BusConfig b;
  b.source_line = c.line_of(n);
  const auto iface = n["interface"];
  if (!iface) c.fail(n, "bus needs an interface (a SocketCAN interface such as can0, or sim)");
  b.interface = c.scalar<std::string>(iface, "interface", "a name");
  if (b.interface.empty() || b.interface.size() > kMaxBusName || b.interface.find('/') != std::string::npos)
    c.fail(iface, "interface " + quoted(b.interface) + " is not a valid interface name (1..15 bytes, no '/')");
  b.name = b.interface;
  if (const auto name = n["name"]) {
    b.name = c.scalar<std::string>(name, "name", "a name");
    if (b.name.empty() || b.name.size() > kMaxBusName)
      c.fail(name, "bus name " + quoted(b.name) + " must be 1..15 bytes (it is a DDS key, string<15>)");
  }
  if (const auto r = n["bitrate"]) {
    b.bitrate = static_cast<std::uint32_t>(c.integer(r, "bitrate", 1, 1000000));
    if (!codec::supports_bitrate(std::nullopt, b.bitrate))
      c.fail(r, "bitrate " + r.Scalar() + " is not one the PMU supports (125000, 250000, 500000, 1000000)");
  }
  if (const auto d = n["discover"]) {
    if (d.IsScalar()) {
      b.discover = c.scalar<bool>(d, "discover", "true, false or a mapping of device settings");
    } else {
      c.only_keys(d, "discover",
                  {"mode", "period", "packets", "configure_streaming", "engine_running_rpm", "engine_running_hold",
                   "min_firmware", "alarms"});
      b.discover = true;
      parse_device_settings(c, d, b.discovered_defaults);
    }
  }
  if (const auto devs = n["devices"]) {
    if (!devs.IsSequence()) c.fail(devs, "devices must be a list");
    std::set<std::uint16_t> seen;
    for (const auto& dn : devs) {
      DeviceConfig d = parse_device(c, dn, b);
      if (!seen.insert(d.address).second)
        c.fail(dn, "address " + std::to_string(d.address) + " appears twice on bus " + b.name);
      b.devices.push_back(d);
    }
  }
  if (const auto v = n["batteries"]) parse_batteries(c, v, b);
  if (const auto v = n["mppts"]) parse_mppts(c, v, b);
  if (const auto v = n["listen_canopen"]) b.listen_canopen = c.scalar<bool>(v, "listen_canopen", "true or false");
  if (const auto v = n["alarms"]) b.alarms = parse_alarm_settings(v, alarms::DeviceKind::Bus, c.source);
  if (b.devices.empty() && !b.discover && !b.wants_canopen())
    c.fail(n, "bus " + b.name + " has no devices, batteries or mppts, and discover and listen_canopen are off");
  return b;
}

void parse_timeouts(const Ctx& c, const YAML::Node& n, Timeouts& t) {
  c.only_keys(n, "timeouts", {"reply", "retries", "stale_periods", "offline_periods", "send"});
  if (const auto v = n["reply"])
    t.reply = std::chrono::milliseconds(std::lround(c.number(v, "reply", 0.01, 10) * 1000));
  if (const auto v = n["retries"]) t.retries = static_cast<unsigned>(c.integer(v, "retries", 0, 10));
  if (const auto v = n["stale_periods"]) t.stale_periods = c.number(v, "stale_periods", 1.5, 100);
  if (const auto v = n["offline_periods"]) t.offline_periods = c.number(v, "offline_periods", 2, 1000);
  if (const auto v = n["send"]) t.send = std::chrono::milliseconds(std::lround(c.number(v, "send", 0, 5) * 1000));
  if (t.offline_periods <= t.stale_periods)
    c.fail(n["offline_periods"] ? n["offline_periods"] : n, "offline_periods must be greater than stale_periods");
}

// ---- `redundancy:` (pmu/redundancy/settings.hpp, docs/interface.md section 4.7) ----

// A period in seconds, in whole milliseconds: what the role machine counts in.
redundancy::Duration redundancy_period(const Ctx& c, const YAML::Node& n, const char* name, redundancy::Duration lo,
                                       redundancy::Duration hi) {
  const double s = c.number(n, name, static_cast<double>(lo.count()) / 1000, static_cast<double>(hi.count()) / 1000);
  const double ms = s * 1000;
  if (std::fabs(ms - std::round(ms)) > 1e-6)
    c.fail(n, std::string(name) + " " + n.Scalar() + " is not whole milliseconds");
  return redundancy::Duration(std::lround(ms));
}

// The instance names of pmu/role's key: what a host name may hold.
bool is_instance_name(const std::string& name) {
  return !name.empty() && name.size() <= 63 && std::all_of(name.begin(), name.end(), [](char ch) {
    return std::isalnum(static_cast<unsigned char>(ch)) != 0 || ch == '-' || ch == '_' || ch == '.';
  });
}

// Without `name:`, the host's name up to its first dot, cut to an instance name's 63
// characters; "pmu-service" where the host has none an instance name can hold.
std::string host_instance_name() {
  char buf[256] = {};
  if (::gethostname(buf, sizeof buf - 1) != 0) return "pmu-service";
  std::string h(buf);
  h = h.substr(0, h.find('.'));
  if (h.size() > 63) h.resize(63);
  return is_instance_name(h) ? h : "pmu-service";
}

redundancy::Settings parse_redundancy(const Ctx& c, const YAML::Node& n) {
  if (!n.IsMap()) c.fail(n, "redundancy must be a map: {priority: 2, peer: mc-b}");
  c.only_keys(n, "redundancy", {"priority", "peer", "name", "heartbeat_period", "lease", "can_silence"});
  redundancy::Settings r;
  const auto priority = n["priority"];
  if (!priority) c.fail(n, "redundancy needs priority (1..255; the higher wins when neither instance owns the bus)");
  r.priority = static_cast<std::uint8_t>(c.integer(priority, "redundancy priority", redundancy::kMinPriority, 255));
  const auto peer = n["peer"];
  if (!peer) c.fail(n, "redundancy needs peer (the other instance's name)");
  r.peer = peer.IsNull() ? std::string() : c.scalar<std::string>(peer, "redundancy peer", "a name");
  if (!is_instance_name(r.peer)) {
    // `peer:` with nothing after it is YAML null, whose mark is the next line: name the key's.
    const auto key = [&]() -> YAML::Node {
      for (const auto& kv : n)
        if (kv.first.Scalar() == "peer") return kv.first;
      return peer;
    };
    c.fail(peer.IsNull() ? key() : peer,
           "redundancy peer " + quoted(r.peer) +
               " is not an instance name (1..63 letters, digits, '-', '_' or '.', as a host name)");
  }
  if (const auto v = n["name"]) {
    r.name = v.IsNull() ? std::string() : c.scalar<std::string>(v, "redundancy name", "a name");
    if (!is_instance_name(r.name))
      c.fail(v, "redundancy name " + quoted(r.name) +
                    " is not an instance name (1..63 letters, digits, '-', '_' or '.', as a host name)");
  } else {
    r.name = host_instance_name();
  }
  if (const auto v = n["heartbeat_period"])
    r.heartbeat_period = redundancy_period(c, v, "redundancy heartbeat_period", redundancy::kMinHeartbeatPeriod,
                                           redundancy::kMaxHeartbeatPeriod);
  if (const auto v = n["lease"])
    r.lease = redundancy_period(c, v, "redundancy lease", redundancy::Duration{1}, redundancy::kMaxLease);
  if (const auto v = n["can_silence"])
    r.can_silence =
        redundancy_period(c, v, "redundancy can_silence", redundancy::kMinCanSilence, redundancy::kMaxCanSilence);
  // The lease against the heartbeat period: at the line of whichever of the two is written.
  if (const auto why = redundancy::settings_problem(r); !why.empty())
    c.fail(n["lease"] ? n["lease"] : n["heartbeat_period"] ? n["heartbeat_period"] : n, "redundancy " + why);
  return r;
}

void parse_ros2(const Ctx& c, const YAML::Node& n, dds::Ros2Settings& r) {
  if (!n.IsMap()) c.fail(n, "ros2 must be a map: {enabled: true, namespace: /fleet}");
  c.only_keys(n, "ros2", {"enabled", "namespace"});
  r.source_line = c.line_of(n);
  if (const auto v = n["enabled"]) r.enabled = c.scalar<bool>(v, "ros2 enabled", "true or false");
  if (const auto v = n["namespace"]) {
    if (!v.IsNull()) r.name_space = c.scalar<std::string>(v, "ros2 namespace", "a ROS 2 namespace");
    if (const auto why = dds::ros2_namespace_problem(r.name_space); !why.empty())
      c.fail(v, "ros2 namespace " + quoted(r.name_space) + " " + why);
  }
}

void parse_link(const Ctx& c, const YAML::Node& n, dds::LinkSettings& link) {
  if (!n.IsMap()) c.fail(n, "link must be a map: {profile: radio} and/or {round_trip: SECONDS}");
  c.only_keys(n, "link", {"profile", "round_trip"});
  const auto profile = n["profile"];
  const auto v = n["round_trip"];
  if (!profile && !v)
    c.fail(n, std::string("link needs profile (") + dds::kLinkProfileNames +
                  ") or round_trip: the link's round trip in seconds, 0.001..30");
  if (profile) {
    const auto text = c.scalar<std::string>(profile, "link profile", "radio or none");
    const auto p = dds::parse_link_profile(text);
    if (!p) c.fail(profile, "link profile " + quoted(text) + " is not one of: " + dds::kLinkProfileNames);
    link.profile = *p;
    link.profile_where = c.line_of(profile);
  }
  if (v) {
    const double s = c.number(v, "link round_trip", 0, 30);
    if (s < 0.001) c.fail(v, "link round_trip " + v.Scalar() + " is below 0.001 s");
    link.round_trip = std::chrono::milliseconds(std::lround(s * 1000));
    link.round_trip_where = c.line_of(v);
  }
}

void parse_policy(const Ctx& c, const YAML::Node& n, PolicyConfig& p) {
  c.only_keys(n, "policy", {"confirm", "deny", "rate_limit", "burst", "command_lifetime", "max_command_lifetime"});
  if (const auto v = n["confirm"]) {
    if (!v.IsSequence()) c.fail(v, "confirm must be a list of rule names (may be empty: [])");
    p.confirm.fill(false);
    for (const auto& item : v) {
      const auto name = c.scalar<std::string>(item, "confirm rule", "a name");
      const auto rule = confirm_rule_from_name(name);
      if (!rule) c.fail(item, "unknown confirm rule " + quoted(name) + " (known: " + confirm_rule_names() + ")");
      p.confirm[static_cast<std::size_t>(*rule)] = true;
    }
  }
  if (const auto v = n["deny"]) {
    if (!v.IsSequence()) c.fail(v, "deny must be a list of command kinds");
    for (const auto& item : v) {
      const auto name = c.scalar<std::string>(item, "command", "a name");
      const auto kind = command_kind_from_name(name);
      if (!kind) c.fail(item, "unknown command " + quoted(name) + " in deny");
      if (*kind == CommandKind::EngineStop) c.fail(item, "engine_stop cannot be denied: it is the safety stop");
      p.deny[static_cast<std::size_t>(*kind)] = true;
    }
  }
  if (const auto v = n["rate_limit"]) p.rate_per_second = c.number(v, "rate_limit", 0, 1000);
  if (const auto v = n["burst"]) p.burst = c.number(v, "burst", 1, 10000);
  auto& lt = p.lifetimes;
  if (const auto v = n["command_lifetime"])
    lt.default_lifetime = std::chrono::milliseconds(std::lround(c.number(v, "command_lifetime", 0.1, 3600) * 1000));
  if (const auto v = n["max_command_lifetime"])
    lt.max_lifetime = std::chrono::milliseconds(std::lround(c.number(v, "max_command_lifetime", 0.1, 3600) * 1000));
  if (lt.max_lifetime < lt.default_lifetime) {
    if (n["max_command_lifetime"])
      c.fail(n["max_command_lifetime"], "max_command_lifetime must be at least command_lifetime");
    lt.max_lifetime = lt.default_lifetime;  // only the default was raised: the cap follows it
  }
}

// "/etc/pmu-dds/" for "/etc/pmu-dds/pmu-service.yaml": what a relative path in it is relative to.
std::string config_folder(const std::string& source) {
  const auto slash = source.rfind('/');
  return slash == std::string::npos ? std::string() : source.substr(0, slash + 1);
}

// `credential:NAME` in a security path: the file systemd's LoadCredential=NAME:... gave the
// unit, so a root-only key reaches the transient service user without being readable by it
// where it is stored. Resolved here, once, so the rest of the service sees a plain path.
constexpr const char* kCredentialPrefix = "credential:";

std::string credential_path(const Ctx& c, const YAML::Node& at, const char* key, const std::string& name) {
  if (name.empty() || name == "." || name == ".." || name.find('/') != std::string::npos)
    c.fail(at, std::string(key) + ": '" + name +
                   "' is not a credential name (credential:NAME, NAME as in LoadCredential=NAME:PATH, no '/')");
  if (!c.env.credentials_directory || c.env.credentials_directory->empty())
    c.fail(at, std::string(key) + ": credential:" + name +
                   " needs $CREDENTIALS_DIRECTORY, which is not set: the service was not started by systemd with "
                   "LoadCredential=" +
                   name + ":PATH (deploy/security/README.md)");
  std::string dir = *c.env.credentials_directory;
  if (dir.back() != '/') dir += '/';
  return dir + name;
}

// security: the six files (all or none) and warn_days. Paths relative to the config file,
// or credential:NAME.
void parse_security(const Ctx& c, const YAML::Node& key, const YAML::Node& n, SecurityConfig& sec) {
  if (!n.IsMap()) c.fail(key, "security must be a mapping of the six files (see deploy/security/README.md)");
  c.only_keys(n, "security",
              {"identity_ca", "identity_certificate", "private_key", "permissions_ca", "governance", "permissions",
               "warn_days"});
  sec.source_line = c.line_of(key);
  const std::string base = config_folder(c.source);
  std::string missing;
  for (const auto& ref : dds::kSecurityFileKeys) {
    const auto v = n[ref.key];
    if (!v) {
      missing += std::string(missing.empty() ? "" : ", ") + ref.key;
      continue;
    }
    std::string path = c.scalar<std::string>(v, ref.key, "a path");
    if (path.empty()) c.fail(v, std::string(ref.key) + " must be a path to a file, not empty");
    if (path.rfind(kCredentialPrefix, 0) == 0) {
      path = credential_path(c, v, ref.key, path.substr(std::strlen(kCredentialPrefix)));
    } else if (path.front() != '/') {
      path = base + path;
    }
    sec.files.*ref.path = path;
    sec.key_lines[ref.key] = c.line_of(v);
  }
  if (!missing.empty())
    c.fail(key,
           "security needs all six files: " + missing + " missing (or remove the section to run without security)");
  if (const auto v = n["warn_days"]) sec.warn_days = static_cast<int>(c.integer(v, "warn_days", 0, 3650));
}

// discovery: and interfaces: (interface.md 7.2). Each entry is read by dds::parse_address or
// dds::parse_interface, which pmuctl uses too, so both say the same about the same text.
// Names are only checked for form here; they are looked up at start (dds::resolve_network).
// `empty_keeps_position`: an empty string is an entry of its own (a server id left unused),
// kept with an empty host; at least one entry must name something.
std::vector<dds::Address> parse_address_list(const Ctx& c, const YAML::Node& n, const std::string& key,
                                             const std::string& what, const std::string& example,
                                             bool empty_keeps_position = false) {
  if (!n.IsSequence()) c.fail(n, key + " must be a list, e.g. " + example);
  if (n.size() == 0) c.fail(n, key + " must name at least one " + what + ", e.g. " + example);
  std::vector<dds::Address> out;
  std::set<std::pair<std::string, std::uint16_t>> seen;
  for (const auto& item : n) {
    if (!item.IsScalar()) c.fail(item, what + " must be a single address, e.g. " + example);
    dds::Address a;
    a.text = item.Scalar();
    a.where = c.line_of(item);
    if (empty_keeps_position && a.text.empty()) {
      out.push_back(std::move(a));
      continue;
    }
    const std::string why = what == "interface" ? dds::parse_interface(a.text, a) : dds::parse_address(a.text, a);
    if (!why.empty()) c.fail(item, what + " " + quoted(a.text) + ": " + why);
    std::string host = a.host;  // host names are case-insensitive
    std::transform(host.begin(), host.end(), host.begin(), [](unsigned char ch) { return std::tolower(ch); });
    if (!seen.insert({host, a.port}).second) c.fail(item, what + " " + quoted(a.text) + " appears twice in " + key);
    out.push_back(std::move(a));
  }
  if (std::all_of(out.begin(), out.end(), [](const dds::Address& a) { return a.host.empty(); }))
    c.fail(n, key + " must name at least one " + what + " (an empty entry only leaves its id unused), e.g. " + example);
  return out;
}

// The value of `key` in `map`, or the key itself when the value is empty (`peers:` alone):
// an empty value has no position of its own, so messages point at its key's line.
std::optional<YAML::Node> value_or_key(const YAML::Node& map, const char* key) {
  for (const auto& kv : map)
    if (kv.first.as<std::string>() == key) return kv.second.IsNull() ? kv.first : kv.second;
  return std::nullopt;
}

void parse_discovery(const Ctx& c, const YAML::Node& key, const YAML::Node& n, dds::Transport transport,
                     dds::NetworkConfig& net) {
  if (!n.IsMap()) c.fail(key, "discovery must be a mapping: mode (multicast, unicast or server), peers, servers");
  c.only_keys(n, "discovery", {"mode", "peers", "servers"});
  const YAML::Node mode = n["mode"];
  if (mode && mode.IsNull()) c.fail(*value_or_key(n, "mode"), "discovery mode must be multicast, unicast or server");
  if (mode) {
    const auto m = c.scalar<std::string>(mode, "discovery mode", "multicast, unicast or server");
    if (m == "unicast")
      net.mode = dds::DiscoveryMode::Unicast;
    else if (m == "server")
      net.mode = dds::DiscoveryMode::Server;
    else if (m != "multicast")
      c.fail(mode, "discovery mode " + quoted(m) + " is not one of multicast, unicast, server");
  }
  const std::string mode_name = dds::to_string(net.mode);
  const YAML::Node at = mode ? mode : key;
  if (const auto v = value_or_key(n, "peers")) {
    const YAML::Node& p = *v;
    if (net.mode != dds::DiscoveryMode::Unicast)
      c.fail(p, "peers are for discovery mode unicast, not " + mode_name + " (set mode: unicast, or remove peers)");
    net.peers = parse_address_list(c, p, "peers", "peer", "[192.168.10.2, \"10.0.0.7:7412\", gcs.local]");
  }
  if (const auto v = value_or_key(n, "servers")) {
    const YAML::Node& s = *v;
    if (net.mode != dds::DiscoveryMode::Server)
      c.fail(s, "servers are for discovery mode server, not " + mode_name + " (set mode: server, or remove servers)");
    net.servers = parse_address_list(c, s, "servers", "server", "[\"10.0.0.1:11811\"]", true);
    if (net.servers.size() > dds::kMaxServers)
      c.fail(s[dds::kMaxServers], "more than " + std::to_string(dds::kMaxServers) + " servers (server ids are 0..255)");
  }
  if (net.mode == dds::DiscoveryMode::Unicast && net.peers.empty())
    c.fail(at,
           "discovery mode unicast needs peers: a list of IPv4 addresses or host names, each with an optional "
           ":PORT");
  if (net.mode == dds::DiscoveryMode::Server && net.servers.empty())
    c.fail(at,
           "discovery mode server needs servers: the Discovery Servers' ADDRESS[:PORT] (port 11811 if none), "
           "in server id order");
  if (net.mode != dds::DiscoveryMode::Multicast && transport == dds::Transport::ShmOnly)
    c.fail(at, "discovery mode " + mode_name +
                   " reaches other hosts over UDP, but dds_transport is shm "
                   "(shared memory only): set dds_transport to udp or default");
}

void parse_interfaces(const Ctx& c, const YAML::Node& key, const YAML::Node& n, dds::Transport transport,
                      dds::NetworkConfig& net) {
  if (transport == dds::Transport::ShmOnly)
    c.fail(key,
           "interfaces restrict DDS over UDP, but dds_transport is shm (shared memory only, no network): "
           "set dds_transport to udp or default, or remove interfaces");
  // A bare `interfaces:` has no position of its own: report the key's line.
  net.interfaces = parse_address_list(c, n.IsNull() ? key : n, "interfaces", "interface", "[eth1, 192.168.10.1]");
}

// dds_statistics: `all`, or a list of Fast DDS statistics topic names (statistics_settings.hpp).
// Fast DDS only logs a name it does not know and goes on without it; here it is refused at
// its line, with the names that exist.
std::vector<std::string> parse_statistics(const Ctx& c, const YAML::Node& key, const YAML::Node& n) {
  const auto& known = dds::statistics_topic_names();
  if (n.IsScalar() && n.Scalar() == "all") return known;
  if (n.IsNull()) c.fail(key, "dds_statistics must be all or a list of statistics topic names (may be empty: [])");
  if (!n.IsSequence())
    c.fail(n, "dds_statistics must be all or a list of statistics topic names, e.g. [" + known.front() + "]");
  std::vector<std::string> topics;
  for (const auto& item : n) {
    const auto name = c.scalar<std::string>(item, "statistics topic", "a name");
    if (!dds::is_statistics_topic(name)) {
      std::string list;
      for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
      c.fail(item, "unknown statistics topic " + quoted(name) + " (known: " + list + ")");
    }
    if (std::find(topics.begin(), topics.end(), name) != topics.end())
      c.fail(item, "statistics topic " + quoted(name) + " appears twice in dds_statistics");
    topics.push_back(name);
  }
  return topics;
}

// Counts documents; nothing else of the stream is kept.
class DocumentStarts : public YAML::EventHandler {
 public:
  std::vector<YAML::Mark> starts;
  void OnDocumentStart(const YAML::Mark& mark) override { starts.push_back(mark); }
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark&, YAML::anchor_t) override {}
  void OnAlias(const YAML::Mark&, YAML::anchor_t) override {}
  void OnScalar(const YAML::Mark&, const std::string&, YAML::anchor_t, const std::string&) override {}
  void OnSequenceStart(const YAML::Mark&, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {}
  void OnSequenceEnd() override {}
  void OnMapStart(const YAML::Mark&, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {}
  void OnMapEnd() override {}
};

// YAML::Load reads the first document and drops the rest: a second one (after `---`) would
// be ignored whole. Throws YAML::ParserException for a syntax error.
void refuse_second_document(const Ctx& c, const std::string& text) {
  std::istringstream in(text);
  YAML::Parser parser(in);
  DocumentStarts docs;
  while (docs.starts.size() < 2 && parser.HandleNextDocument(docs)) {
  }
  if (docs.starts.size() > 1)
    throw ConfigError(c.source + ":" + std::to_string(docs.starts[1].line + 1) +
                      ": a second YAML document ('---'): the config is one document; merge it into the first");
}

// Every mapping, at any depth: each key once, and a key is a name (a scalar).
void refuse_duplicate_keys(const Ctx& c, const YAML::Node& n) {
  if (n.IsSequence()) {
    for (const auto& item : n) refuse_duplicate_keys(c, item);
    return;
  }
  if (!n.IsMap()) return;
  std::map<std::string, int> first_line;
  for (const auto& kv : n) {
    if (!kv.first.IsScalar()) c.fail(kv.first, "a key must be a name, not a list or mapping");
    const int line = kv.first.Mark().line + 1;
    const auto [it, fresh] = first_line.emplace(kv.first.Scalar(), line);
    if (!fresh)
      c.fail(kv.first, "key " + quoted(kv.first.Scalar()) + " appears twice in one mapping (first on line " +
                           std::to_string(it->second) + "); give each key once");
    refuse_duplicate_keys(c, kv.second);
  }
}

const char* const kLogLevels[] = {"trace", "debug", "info", "warn", "error", "critical", "off"};

}  // namespace

bool is_log_level(const std::string& level) {
  return std::find(std::begin(kLogLevels), std::end(kLogLevels), level) != std::end(kLogLevels);
}

Config parse_config(const std::string& text, const std::string& source, const ConfigEnvironment& env) {
  const Ctx c{source, env};
  YAML::Node root;
  try {
    refuse_second_document(c, text);
    root = YAML::Load(text);
  } catch (const YAML::ParserException& e) {
    throw ConfigError(source + ":" + std::to_string(e.mark.line + 1) + ": YAML syntax error: " + e.msg);
  }
  Config cfg;
  cfg.source = source;
  if (root.IsNull()) throw ConfigError(source + ":1: the file is empty");
  // Before any key is read: yaml-cpp keeps both of two equal keys, and n["key"] finds the first.
  refuse_duplicate_keys(c, root);
  c.only_keys(root, "the top level",
              {"domain", "vehicle", "low_rate_period", "qos_file", "dds_transport", "log_level", "buses", "timeouts",
               "policy", "security", "discovery", "interfaces", "canopen_publish_period", "dds_statistics",
               "dds_type_objects", "also_serve_contract", "ros2", "link", "redundancy"});
  if (const auto v = root["domain"]) cfg.domain = static_cast<int>(c.integer(v, "domain", 0, 232));
  if (const auto v = root["vehicle"]) {
    // `vehicle:` with nothing after it is YAML null: the unnamed vehicle, like no key.
    if (!v.IsNull()) cfg.vehicle = c.scalar<std::string>(v, "vehicle", "a name");
    if (const auto why = dds::vehicle_name_problem(cfg.vehicle); !why.empty())
      c.fail(v, "vehicle " + quoted(cfg.vehicle) + " " + why);
  }
  if (const auto v = root["low_rate_period"]) {
    // 0 turns the low-rate topics off; below 0.1 s they would be no slower than a PMU streams.
    const double p = c.number(v, "low_rate_period", 0, 3600);
    if (p != 0 && p < 0.1)
      c.fail(v, "low_rate_period " + v.Scalar() + " is below 0.1 s (0 turns the low-rate topics off)");
    cfg.low_rate_period = std::chrono::milliseconds(std::lround(p * 1000));
  }
  std::chrono::milliseconds canopen_publish_period = BusConfig{}.canopen_publish_period;
  if (const auto v = root["canopen_publish_period"])
    canopen_publish_period =
        std::chrono::milliseconds(std::lround(c.number(v, "canopen_publish_period", 0, 3600) * 1000));
  if (const auto v = root["qos_file"]) {
    // Relative to the config file's folder, as the security files are: the service's working
    // directory is not the config's (systemd runs it in /).
    cfg.qos_file = c.scalar<std::string>(v, "qos_file", "a path");
    if (cfg.qos_file.empty()) c.fail(v, "qos_file must be a path to a file, not empty");
    if (cfg.qos_file.front() != '/') cfg.qos_file = config_folder(source) + cfg.qos_file;
    cfg.qos_file_line = c.line_of(v);
  }
  if (const auto v = root["dds_transport"]) {
    const auto t = c.scalar<std::string>(v, "dds_transport", "default, udp or shm");
    if (t == "udp")
      cfg.dds_transport = dds::Transport::UdpOnly;
    else if (t == "shm")
      cfg.dds_transport = dds::Transport::ShmOnly;
    else if (t != "default")
      c.fail(v, "dds_transport " + quoted(t) + " is not one of default, udp, shm");
  }
  if (const auto v = root["dds_type_objects"])
    cfg.dds_type_objects = c.scalar<bool>(v, "dds_type_objects", "true or false");
  if (const auto v = root["also_serve_contract"]) {
    // One step back only: the service writes the previous contract's names, and converts the
    // types whose layout or meaning changed (dds/include/pmu/dds/previous_contract.hpp).
    const int previous = PMU_CONTRACT_MAJOR - 1;
    const auto n = c.integer(v, "also_serve_contract", 0, 1000);
    if (n != previous)
      c.fail(v, "also_serve_contract " + v.Scalar() + " is not served: this service serves contract " +
                    std::to_string(PMU_CONTRACT_MAJOR) + " and can also serve " + std::to_string(previous) +
                    " only (docs/interface.md section 10)");
    cfg.also_serve_contract = static_cast<int>(n);
  }
  if (const auto v = root["log_level"]) {
    cfg.log_level = c.scalar<std::string>(v, "log_level", "a level");
    if (!is_log_level(cfg.log_level))
      c.fail(v, "log_level " + quoted(cfg.log_level) + " is not one of trace, debug, info, warn, error, critical, off");
  }
  for (const auto& kv : root) {
    const auto key = kv.first.as<std::string>();
    if (key == "discovery") parse_discovery(c, kv.first, kv.second, cfg.dds_transport, cfg.network);
    if (key == "interfaces") parse_interfaces(c, kv.first, kv.second, cfg.dds_transport, cfg.network);
    if (key == "dds_statistics") {
      cfg.dds_statistics = parse_statistics(c, kv.first, kv.second);
      cfg.dds_statistics_line = c.line_of(kv.first);
    }
  }
  if (const auto v = root["timeouts"]) parse_timeouts(c, v, cfg.timeouts);
  if (const auto v = root["ros2"]) parse_ros2(c, v, cfg.ros2);
  for (const auto& kv : root)
    if (kv.first.as<std::string>() == "redundancy") {
      cfg.redundancy = parse_redundancy(c, kv.second);
      cfg.redundancy_line = c.line_of(kv.first);
    }
  if (const auto v = root["link"]) {
    parse_link(c, v, cfg.network.link);
    cfg.network.link.low_rate_period_given = static_cast<bool>(root["low_rate_period"]);
    const auto plan = dds::link_plan(cfg.network.link);
    if (plan.low_rate_period.set()) cfg.low_rate_period = plan.low_rate_period.value;
  }
  if (const auto v = root["policy"]) parse_policy(c, v, cfg.policy);
  for (const auto& kv : root)
    if (kv.first.as<std::string>() == "security") parse_security(c, kv.first, kv.second, cfg.security);
  // Both sections are read by now; what one says about the other is checked here.
  if (cfg.network.mode == dds::DiscoveryMode::Server && !cfg.security.files.empty()) {
    const auto d = root["discovery"];
    c.fail(d["mode"] ? d["mode"] : d, std::string("discovery mode server ") + dds::kServerWithSecurity);
  }
  const auto buses = root["buses"];
  if (!buses) c.fail(root, "no buses: the service needs at least one bus");
  if (!buses.IsSequence() || buses.size() == 0) c.fail(buses, "buses must be a non-empty list");
  std::set<std::string> names, interfaces;
  std::map<std::string, std::string> ros2_names;  // ROS 2 token -> the bus name it came from
  std::size_t devices = 0;
  for (const auto& bn : buses) {
    BusConfig b = parse_bus(c, bn);
    b.canopen_publish_period = canopen_publish_period;
    // The QoS profiles hold dds::kMaxDevicesPerService instances per writer; past that Fast DDS
    // would refuse the extra PMUs' samples at run time.
    if (devices + b.devices.size() > dds::kMaxDevicesPerService)
      c.fail(bn["devices"][dds::kMaxDevicesPerService - devices],
             "more than " + std::to_string(dds::kMaxDevicesPerService) +
                 " devices in one service (the capacity its DDS writers are sized for, "
                 "pmu::dds::kMaxDevicesPerService); split them across services");
    devices += b.devices.size();
    // Batteries and MPPTs are instances of pmu/health too.
    const std::size_t canopen = b.batteries.size() + b.mppts.size();
    if (devices + canopen > dds::kMaxDevicesPerService)
      c.fail(bn[b.batteries.empty() ? "mppts" : "batteries"],
             "more than " + std::to_string(dds::kMaxDevicesPerService) +
                 " devices (PMUs, batteries and MPPTs) in one service (the capacity its DDS writers are sized for, "
                 "pmu::dds::kMaxDevicesPerService); split them across services");
    devices += canopen;
    if (!names.insert(b.name).second) c.fail(bn, "bus name " + quoted(b.name) + " appears twice");
    // ROS 2 names allow fewer characters than bus names: two buses must not share one.
    if (cfg.ros2.enabled && !ros2_names.emplace(dds::ros2_token(b.name), b.name).second)
      c.fail(bn, "bus names " + quoted(ros2_names[dds::ros2_token(b.name)]) + " and " + quoted(b.name) + " are both " +
                     quoted(dds::ros2_token(b.name)) + " in ROS 2 topic names (ros2 enabled); rename one");
    if (b.interface != "sim" && !interfaces.insert(b.interface).second)
      c.fail(bn, "interface " + quoted(b.interface) + " is used by two buses (the service owns each bus alone)");
    cfg.buses.push_back(std::move(b));
  }
  return cfg;
}

std::string SecurityConfig::line_of(const std::string& key) const {
  const auto it = key_lines.find(key);
  return it != key_lines.end() ? it->second : source_line;
}

Config load_config(const std::string& path) {
  // Bounded and regular only: a device or FIFO named as the config must not hang or exhaust
  // the start (docs/safety.md H12).
  auto file = files::read_bounded_file(path, kMaxConfigFileBytes);
  if (!file.ok()) throw ConfigError(path + ": cannot read the config file: " + file.error);
  ConfigEnvironment env;
  if (const char* dir = std::getenv("CREDENTIALS_DIRECTORY"); dir != nullptr) env.credentials_directory = dir;
  return parse_config(file.text, path, env);
}

Config default_sim_config() {
  Config cfg;
  cfg.source = "<built-in simulator>";
  BusConfig b;
  b.name = "sim0";
  b.interface = "sim";
  b.source_line = cfg.source;
  DeviceConfig d;
  d.address = 1;
  d.period = std::chrono::milliseconds(500);
  b.devices.push_back(d);
  cfg.buses.push_back(b);
  return cfg;
}

void override_bus(Config& config, const std::string& spec) {
  std::string iface;
  if (spec == "sim") {
    iface = "sim";
  } else if (spec.rfind("socketcan:", 0) == 0) {
    iface = spec.substr(10);
    if (iface.empty() || iface.size() > kMaxBusName || iface == "sim")
      throw ConfigError("--bus " + spec + ": " + quoted(iface) + " is not a valid interface name");
  } else if (spec.rfind("fd:", 0) == 0) {
    // An inherited fd carrying struct can_frame records (one end of a socketpair): how the
    // benchmarks drive the SocketCAN code path on a kernel without CAN.
    const std::string n = spec.substr(3);
    int fd = -1;
    const auto r = std::from_chars(n.data(), n.data() + n.size(), fd);
    if (n.empty() || r.ec != std::errc{} || r.ptr != n.data() + n.size() || fd < 3)
      throw ConfigError("--bus " + spec + ": expected fd:N with an inherited file descriptor N >= 3");
    iface = spec;
  } else {
    throw ConfigError("--bus " + spec + ": expected sim or socketcan:IFACE");
  }
  BusConfig b = config.buses.empty() ? default_sim_config().buses.front() : config.buses.front();
  // The simulator's settings mean nothing on a real bus; `--bus` picks the bus over the file.
  if (iface != "sim") b.sim = {};
  b.interface = iface;
  b.name = iface == "sim" ? "sim0" : iface.rfind("fd:", 0) == 0 ? "fd" + iface.substr(3) : iface;
  b.source_line = "--bus " + spec;
  config.buses.assign(1, b);
}

}  // namespace pmu::service
