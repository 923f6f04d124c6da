#pragma once
// pmu-service configuration: a YAML file (deploy/pmu-service.yaml documents every key)
// with command-line overrides. Loading is start-up, so errors throw ConfigError whose
// message is "FILE:LINE: what is wrong"; main prints it and exits non-zero before anything
// is opened, so a bad config never sends a frame.

#include <chrono>
#include <cstdint>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "pmu/alarms/settings.hpp"
#include "pmu/baseline/config_file.hpp"
#include "pmu/codec/messages.hpp"
#include "pmu/command/policy.hpp"
#include "pmu/dds_settings/capacity.hpp"
#include "pmu/dds_settings/network_settings.hpp"
#include "pmu/dds_settings/ros2_names.hpp"
#include "pmu/config/sim_settings.hpp"
#include "pmu/dds_settings/transport_choice.hpp"
#include "pmu/redundancy/settings.hpp"
#include "pmu/security/security_files.hpp"

namespace pmu::service {

// The largest config file read (interface.md 4.1): far above any real one, and a bound, so a
// device or a runaway file named as the config is refused (docs/safety.md H12).
inline constexpr std::size_t kMaxConfigFileBytes = std::size_t{1} << 20;

class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

enum class TelemetryMode : std::uint8_t {
  Streaming,  // the PMU streams what its PS selects every PP; the service listens
  Polling,    // the service asks: 0x0F from firmware 1.14, single gets before
};

// When a verified engine start counts as started (interface.md 2.7). The PMU document gives
// no running speed, so the default is chosen: above what an electric starter turns an engine
// (a few hundred rpm; the simulator cranks at 300) and below the idle of the engines such a
// PMU is fitted to. One second at that speed tells a running engine from a cough.
struct EngineSettings {
  std::uint16_t running_rpm = 1500;
  std::chrono::milliseconds running_hold{1000};
};

struct DeviceConfig {
  std::uint16_t address = 1;
  TelemetryMode mode = TelemetryMode::Streaming;
  // Polling: the poll period. Streaming: the packet period expected (PP); with
  // `configure_streaming` it is written to the PMU when the PMU's own PP differs.
  std::chrono::milliseconds period{1000};
  std::uint8_t groups = codec::group_bit::All;  // measurement groups, codec::kGroupNames
  // Streaming only: write PP and PS to the PMU when they differ from period/groups. Off by
  // default: they live in the PMU's non-volatile memory and belong to whoever set it up.
  bool configure_streaming = false;
  EngineSettings engine;
  // `alarms:` (interface.md 1.6): what this unit changes of the alarm table's defaults;
  // checked by alarms::resolve when the config is read.
  alarms::DeviceSettings alarms;
  // The vehicle is not ready while the unit's firmware is older (interface.md 1.7).
  std::optional<codec::FirmwareVersion> min_firmware;
  // `baseline:` (interface.md 4.1): the configuration file the unit's settings are watched
  // against, read and checked with the config; none when unset (always for a discovered
  // PMU). `baseline_file` as the config writes it (pmu/baseline carries it), `baseline_path`
  // the file read (a relative one is relative to the config file's folder).
  std::optional<baseline::ConfigFile> baseline;
  std::string baseline_file;
  std::string baseline_path;
  // "FILE:LINE" of its `address:` in the config file, for the line to change when the unit
  // moves; empty for a device not from a file (discovered, built in).
  std::string source_line;
};

// A battery (MG BMS) on the bus, read-only (spec/solar-boat-canopen-battery-mppt.txt). The
// document gives one set of COB-IDs (0x202, 0x302, 0x402, 0x482): node 2.
struct BatteryConfig {
  std::uint8_t node = 2;
  // Seconds between a BMS's frames of one value: health goes STALE after stale_periods and
  // OFFLINE after offline_periods of these without a frame.
  std::chrono::milliseconds period{1000};
  alarms::DeviceSettings alarms;  // as DeviceConfig::alarms
  // Ah, the nameplate capacity (> 0): with the state of charge it gives pmu/bms_energy's
  // endurance. Unset: no endurance, as the BMS does not send its capacity.
  std::optional<double> capacity_ah;
};

// An MPPT on the bus, read-only; `device` 0..7 selects COB-IDs 0x4E6 + 8 x device (and + 1).
struct MpptConfig {
  std::uint8_t device = 0;
  std::chrono::milliseconds period{1000};  // as BatteryConfig::period
  alarms::DeviceSettings alarms;           // as DeviceConfig::alarms
};

struct BusConfig {
  std::string name;                 // the DDS key `bus`; at most 15 bytes
  std::string interface;            // SocketCAN interface, or "sim" for the built-in simulated PMU
  std::uint32_t bitrate = 1000000;  // what the link runs at (checked against the firmware)
  std::vector<DeviceConfig> devices;
  bool discover = false;             // find PMUs by a broadcast firmware request at start
  DeviceConfig discovered_defaults;  // settings for PMUs found by discovery
  std::vector<BatteryConfig> batteries;
  std::vector<MpptConfig> mppts;
  // Also serve batteries and MPPTs heard on the bus but not listed (with a period of 1 s).
  bool listen_canopen = false;
  // `alarms:` of the bus's own alarms (bus_error_passive, bus_off).
  alarms::DeviceSettings alarms;
  // True when the bus serves any battery or MPPT: its receive filters must pass CANopen ids.
  // pmu/battery, pmu/battery_cells and pmu/mppt get at most one sample per device per this
  // period (0: one per bus-loop turn that brought a value). The config's top-level
  // canopen_publish_period, the same for every bus.
  std::chrono::milliseconds canopen_publish_period{200};
  bool wants_canopen() const noexcept { return listen_canopen || !batteries.empty() || !mppts.empty(); }
  std::string source_line;  // "FILE:LINE" of the bus entry, for later messages
  // The devices' `sim:` mappings (sim_settings.hpp); only on an `interface: sim` bus.
  BusSimSettings sim;
};

struct Timeouts {
  std::chrono::milliseconds reply{250};  // wait for an answer to one get
  unsigned retries = 2;                  // extra tries of an idempotent get
  double stale_periods = 3;              // no frame for this many periods -> STALE
  double offline_periods = 10;           // -> OFFLINE (and re-read info/config on return)
  std::chrono::milliseconds send{100};   // wait for room in the transmit queue
};

// DDS-Security (the `security:` section). All six files or none; relative paths are taken
// relative to the config file's folder. Checked at start-up (dds::check_security_files)
// before any participant or bus is opened.
struct SecurityConfig {
  dds::SecurityFiles files;  // empty: security off
  int warn_days = 30;        // warn when a certificate or grant ends within this many days
  std::string source_line;   // "FILE:LINE" of the section
  // "FILE:LINE" of each file's key (identity_ca, ...), for the start-up check's messages.
  std::map<std::string, std::string> key_lines;
  // "FILE:LINE" for a file key (the section's line when the key is unknown).
  std::string line_of(const std::string& key) const;
};

struct Config {
  std::string source = "<defaults>";  // the file it came from
  int domain = 0;
  // The vehicle this service belongs to (vehicle.hpp): the first key of every sample and its
  // DDS partition. "" (the default): the unnamed vehicle, in the default partition.
  std::string vehicle;
  // pmu/low_rate/* get each device's telemetry at most once per this period (0: off).
  std::chrono::milliseconds low_rate_period{1000};
  // Empty: the installed deploy/qos.xml, found by the service. Relative in the file: to the
  // config file's folder (made absolute here).
  std::string qos_file;
  std::string qos_file_line;  // "FILE:LINE" of qos_file, for the start-up check's messages
  // default: Fast DDS's builtin transports (shared memory between processes on one host,
  // UDPv4); udp: UDPv4 only, e.g. when readers run as other users (SHM segments are
  // owner-only in Fast DDS 2.9).
  dds::Transport dds_transport = dds::Transport::Default;
  // `discovery:` (multicast, unicast peers, Discovery Server clients) and `interfaces:` (the
  // UDP allowlist); names are resolved at start (dds::resolve_network), not here.
  dds::NetworkConfig network;
  // `dds_statistics`: the Fast DDS statistics topics the participant writes, for Fast DDS
  // Monitor (statistics_settings.hpp); empty (the default): none.
  std::vector<std::string> dds_statistics;
  std::string dds_statistics_line;  // "FILE:LINE" of dds_statistics, for the start-up check
  // `link:` ({profile: radio, round_trip: S}) is network.link (link_profile.hpp). round_trip:
  // the round trip of the slowest link between this service and its readers (a radio to the
  // ground). Its reliable writers then heartbeat at least every 1.5 round trips
  // (dds::DdsContext::heartbeat_at_least): a writer heartbeats every period until each reader
  // has acknowledged, so a period shorter than the round trip sends several heartbeats, each
  // answered, per sample. Unset (the default): qos.xml's periods.
  // `dds_type_objects`: announce the contract's type objects in discovery, for eProsima's
  // dynamic-type tools (dds_type_objects.hpp). Off by default: they add about 10 kB of
  // discovery traffic per joining participant, which a lossy, narrow ground link pays for.
  bool dds_type_objects = false;
  // `also_serve_contract`: the previous major version of the contract, served as well on a
  // second participant for consumers not yet upgraded (docs/interface.md section 10); the
  // only value accepted is the one before this build's. Unset (the default): only this
  // build's contract.
  std::optional<int> also_serve_contract;
  // `ros2`: sensor_msgs/BatteryState and diagnostic_msgs/DiagnosticArray in ROS 2's own
  // names and types (ros2_names.hpp, docs/interface.md section 11).
  dds::Ros2Settings ros2;
  // `redundancy`: this instance of a hot-standby pair (docs/interface.md section 4.7,
  // docs/design.md "Hot standby"); none: a service alone on its buses. Checked by
  // redundancy::settings_problem; `redundancy_line` is the section's FILE:LINE.
  std::optional<redundancy::Settings> redundancy;
  std::string redundancy_line;
  std::string log_level = "info";
  std::vector<BusConfig> buses;
  Timeouts timeouts;
  PolicyConfig policy;
  SecurityConfig security;
};

// What a config may refer to outside its own text, read once at the edge (load_config).
struct ConfigEnvironment {
  // $CREDENTIALS_DIRECTORY: where systemd put the unit's LoadCredential= files. A security
  // path `credential:NAME` is that directory's NAME; unset, such a path is refused.
  std::optional<std::string> credentials_directory;
};

// Parses `path` with this process's environment. Throws ConfigError("path:line: ...") for
// every problem: unknown or repeated keys (at any depth), a second YAML document, wrong
// types, integers not in plain decimal, values out of range, duplicate names/addresses; and
// "path: ..." with the system's reason when the file cannot be opened or read.
Config load_config(const std::string& path);
// Parses YAML text; `source` names it in messages, and a relative `baseline:` is relative to
// its folder. The one file it reads is each device's `baseline:`.
Config parse_config(const std::string& text, const std::string& source, const ConfigEnvironment& env = {});

// What `pmu-service --bus sim` with no config runs: one simulated PMU at address 1 on a bus
// named "sim0", streaming every packet every 0.5 s.
Config default_sim_config();

bool is_log_level(const std::string& level);

// Applies `--bus sim|socketcan:IFACE`: replaces the buses with one bus on that interface
// (keeping the devices of the first configured bus, if any, and their `sim:` settings only
// when the new bus is sim). Throws ConfigError.
void override_bus(Config& config, const std::string& spec);

}  // namespace pmu::service
