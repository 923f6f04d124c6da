// pmu-service configuration: every bad value is refused with FILE:LINE and what is wrong.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <optional>
#include <string>

#include "pmu/config/config.hpp"
#include "pmu/dds_settings/statistics_settings.hpp"

namespace pmu::service {
namespace {

const char* const kGood = R"(domain: 7
log_level: debug
timeouts:
  reply: 0.3
  retries: 1
buses:
  - name: main
    interface: can0
    bitrate: 500000
    devices:
      - address: 1
      - address: 2
        mode: polling
        period: 0.2
        packets: [voltages, status]
        engine_running_rpm: 2200
        engine_running_hold: 0.5
        min_firmware: 1.2
    discover: true
)";

TEST(Config, GoodFileParses) {
  const Config c = parse_config(kGood, "good.yaml");
  EXPECT_EQ(c.domain, 7);
  EXPECT_EQ(c.log_level, "debug");
  EXPECT_EQ(c.timeouts.reply, std::chrono::milliseconds(300));
  EXPECT_EQ(c.timeouts.retries, 1u);
  ASSERT_EQ(c.buses.size(), 1u);
  const BusConfig& b = c.buses[0];
  EXPECT_EQ(b.name, "main");
  EXPECT_EQ(b.interface, "can0");
  EXPECT_EQ(b.bitrate, 500000u);
  EXPECT_TRUE(b.discover);
  ASSERT_EQ(b.devices.size(), 2u);
  EXPECT_EQ(b.devices[0].mode, TelemetryMode::Streaming);
  EXPECT_EQ(b.devices[0].engine.running_rpm, 1500) << "the default";
  EXPECT_EQ(b.devices[0].engine.running_hold, std::chrono::milliseconds(1000));
  EXPECT_EQ(b.devices[1].engine.running_rpm, 2200);
  EXPECT_EQ(b.devices[1].engine.running_hold, std::chrono::milliseconds(500));
  EXPECT_FALSE(b.devices[0].min_firmware) << "no minimum unless configured";
  ASSERT_TRUE(b.devices[1].min_firmware);
  EXPECT_EQ(*b.devices[1].min_firmware, (codec::FirmwareVersion{1, 2})) << "1.2 is minor 2, not 20";
  EXPECT_EQ(b.devices[1].mode, TelemetryMode::Polling);
  EXPECT_EQ(b.devices[1].period, std::chrono::milliseconds(200));
  EXPECT_EQ(b.devices[1].groups, 0x11);
  EXPECT_EQ(b.source_line, "good.yaml:7");
}

TEST(Config, BatteriesAndMpptsParse) {
  const Config c = parse_config(R"(canopen_publish_period: 0.5
buses:
  - interface: can0
    batteries:
      - node: 2
        period: 2.5
        capacity_ah: 20.5
    mppts:
      - device: 0
      - device: 7
        period: 0.1
  - interface: can1
    listen_canopen: true
)",
                                "good.yaml");
  ASSERT_EQ(c.buses.size(), 2u);
  EXPECT_EQ(c.buses[0].canopen_publish_period, std::chrono::milliseconds(500));
  EXPECT_EQ(c.buses[1].canopen_publish_period, std::chrono::milliseconds(500));
  const BusConfig& b = c.buses[0];
  EXPECT_TRUE(b.devices.empty());
  ASSERT_EQ(b.batteries.size(), 1u);
  EXPECT_EQ(b.batteries[0].node, 2);
  EXPECT_EQ(b.batteries[0].period, std::chrono::milliseconds(2500));
  EXPECT_EQ(b.batteries[0].capacity_ah, 20.5);
  ASSERT_EQ(b.mppts.size(), 2u);
  EXPECT_EQ(b.mppts[0].device, 0);
  EXPECT_EQ(b.mppts[0].period, std::chrono::milliseconds(1000));  // the default
  EXPECT_EQ(b.mppts[1].device, 7);
  EXPECT_EQ(b.mppts[1].period, std::chrono::milliseconds(100));
  EXPECT_FALSE(b.listen_canopen);
  EXPECT_TRUE(b.wants_canopen());
  EXPECT_TRUE(c.buses[1].listen_canopen);
  EXPECT_TRUE(c.buses[1].wants_canopen());
  // Defaults: 0.2 s, and a PMU-only bus does not ask for CANopen frames.
  const Config d = parse_config(kGood, "good.yaml");
  EXPECT_EQ(d.buses[0].canopen_publish_period, std::chrono::milliseconds(200));
  EXPECT_FALSE(d.buses[0].wants_canopen());
}

struct BadCase {
  const char* yaml;
  const char* message;  // the whole "FILE:LINE: ..." text
};

// `yaml`, parsed as bad.yaml, is refused with exactly `message`.
void expect_refused(const std::string& yaml, const std::string& message) {
  SCOPED_TRACE(yaml);
  try {
    (void)parse_config(yaml, "bad.yaml");
    ADD_FAILURE() << "accepted";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()), message);
  }
}

const BadCase kBad[] = {
    {"", "bad.yaml:1: the file is empty"},
    {"buses: [\n", "bad.yaml:2: YAML syntax error: end of sequence flow not found"},
    {"domain: 0\n", "bad.yaml:1: no buses: the service needs at least one bus"},
    {"domian: 0\nbuses: []\n",
     "bad.yaml:1: unknown key 'domian' in the top level (known: domain, vehicle, low_rate_period, qos_file, dds_transport, log_level, "
     "buses, timeouts, policy, security, discovery, interfaces, canopen_publish_period, dds_statistics, dds_type_objects, also_serve_contract, ros2, link, redundancy)"},
    {"domain: 0\nvehicle: uav*\nbuses: []\n",
     "bad.yaml:2: vehicle 'uav*' contains '*'; a vehicle name is letters, digits, '_', '-' and '.' (it is also a DDS "
     "partition name, where other characters are patterns)"},
    {"vehicle: a-vehicle-name-16\nbuses: []\n",
     "bad.yaml:1: vehicle 'a-vehicle-name-16' is 17 bytes; a vehicle name has at most 15 (it is a DDS key, "
     "string<15>)"},
    {"vehicle: [uav1]\nbuses: []\n", "bad.yaml:1: vehicle must be a name"},
    {"low_rate_period: 0.05\nbuses: []\n",
     "bad.yaml:1: low_rate_period 0.05 is below 0.1 s (0 turns the low-rate topics off)"},
    {"low_rate_period: -1\nbuses: []\n", "bad.yaml:1: low_rate_period -1 out of range 0..3600"},
    {"domain: 300\nbuses: []\n", "bad.yaml:1: domain 300 out of range 0..232"},
    {"domain: x\nbuses: []\n",
     "bad.yaml:1: domain must be a decimal integer (digits, optionally after '-'; no leading 0, '+', 0x, 0o, exponent "
     "or fraction), not 'x'"},
    {"buses: []\n", "bad.yaml:1: buses must be a non-empty list"},
    {"buses:\n  - name: a\n", "bad.yaml:2: bus needs an interface (a SocketCAN interface such as can0, or sim)"},
    {"buses:\n  - interface: can0\n",
     "bad.yaml:2: bus can0 has no devices, batteries or mppts, and discover and listen_canopen are off"},
    {"buses:\n  - interface: can0\n    batteries:\n      - node: 3\n", "bad.yaml:4: node 3 out of range 2..2"},
    {"buses:\n  - interface: can0\n    batteries:\n      - period: 1\n",
     "bad.yaml:4: battery needs a node (2: COB-IDs 0x202, 0x302, 0x402, 0x482)"},
    {"buses:\n  - interface: can0\n    batteries:\n      - node: 2\n      - node: 2\n",
     "bad.yaml:5: battery node 2 appears twice on bus can0"},
    {"buses:\n  - interface: can0\n    batteries:\n      - node: 2\n        period: 0\n",
     "bad.yaml:5: period 0 out of range 0.01..3600"},
    {"buses:\n  - interface: can0\n    batteries:\n      - node: 2\n        rate: 1\n",
     "bad.yaml:5: unknown key 'rate' in battery (known: node, period, capacity_ah, sim, alarms)"},
    {"buses:\n  - interface: can0\n    batteries: 2\n",
     "bad.yaml:3: batteries must be a list, e.g. [{node: 2, period: 1.0}]"},
    {"buses:\n  - interface: can0\n    mppts:\n      - device: 8\n", "bad.yaml:4: device 8 out of range 0..7"},
    {"buses:\n  - interface: can0\n    mppts:\n      - period: 1\n",
     "bad.yaml:4: mppt needs a device (0..7, set by the MPPT's resistors)"},
    {"buses:\n  - interface: can0\n    mppts:\n      - device: 1\n      - device: 1\n",
     "bad.yaml:5: mppt device 1 appears twice on bus can0"},
    {"buses:\n  - interface: can0\n    listen_canopen: maybe\n",
     "bad.yaml:3: listen_canopen must be true or false, not 'maybe'"},
    {"canopen_publish_period: -0.1\nbuses:\n  - interface: can0\n    discover: true\n",
     "bad.yaml:1: canopen_publish_period -0.1 out of range 0..3600"},
    {"buses:\n  - interface: can0\n    devices:\n      - adress: 1\n",
     "bad.yaml:4: unknown key 'adress' in device (known: address, mode, period, packets, configure_streaming, engine_running_rpm, engine_running_hold, min_firmware, sim, alarms, baseline)"},
    {"buses:\n  - interface: can0\n    devices:\n      - address: 1\n        min_firmware: 1.x\n",
     "bad.yaml:5: min_firmware '1.x' is not MAJOR.MINOR (each 0..255, e.g. \"1.14\")"},
    {"buses:\n  - interface: can0\n    devices:\n      - address: 1\n        min_firmware: 1.2.3\n",
     "bad.yaml:5: min_firmware '1.2.3' is not MAJOR.MINOR (each 0..255, e.g. \"1.14\")"},
    {"buses:\n  - interface: can0\n    discover:\n      min_firmware: 256.0\n",
     "bad.yaml:4: min_firmware '256.0' is not MAJOR.MINOR (each 0..255, e.g. \"1.14\")"},
    {"buses:\n  - interface: can0\n    devices:\n      - address: 1\n        engine_running_rpm: 0\n",
     "bad.yaml:5: engine_running_rpm 0 out of range 1..65534"},
    {"buses:\n  - interface: can0\n    devices:\n      - address: 1\n        engine_running_rpm: 65535\n",
     "bad.yaml:5: engine_running_rpm 65535 out of range 1..65534"},
    {"buses:\n  - interface: can0\n    devices:\n      - address: 1\n        engine_running_hold: 26\n",
     "bad.yaml:5: engine_running_hold 26 out of range 0..25.5"},
    {"buses:\n  - interface: can0\n    discover:\n      engine_running_hold: -1\n",
     "bad.yaml:4: engine_running_hold -1 out of range 0..25.5"},
    {"buses:\n  - interface: can0\n    devices:\n      - address: 65535\n",
     "bad.yaml:4: address 65535 out of range 0..65534"},
    {"buses:\n  - interface: can0\n    devices:\n      - address: 1\n      - address: 1\n",
     "bad.yaml:5: address 1 appears twice on bus can0"},
    {"buses:\n  - interface: can0\n    devices:\n      - address: 1\n        mode: push\n",
     "bad.yaml:5: mode must be streaming or polling, not 'push'"},
    {"buses:\n  - interface: can0\n    devices:\n      - address: 1\n        period: 30\n",
     "bad.yaml:5: period 30 out of range 0.1..25.5"},
    {"buses:\n  - interface: can0\n    devices:\n      - address: 1\n        period: 0.25\n",
     "bad.yaml:5: period must be a multiple of 0.1 s"},
    {"buses:\n  - interface: can0\n    devices:\n      - address: 1\n        packets: [volts]\n",
     "bad.yaml:5: unknown packet 'volts' (known: voltages, currents, battery_energy, temperatures, status)"},
    {"buses:\n  - interface: can0\n    bitrate: 800000\n    discover: true\n",
     "bad.yaml:3: bitrate 800000 is not one the PMU supports (125000, 250000, 500000, 1000000)"},
    {"buses:\n  - interface: averyveryverylongname\n    discover: true\n",
     "bad.yaml:2: interface 'averyveryverylongname' is not a valid interface name (1..15 bytes, no '/')"},
    {"buses:\n  - interface: can0\n    discover: true\n  - interface: can0\n    name: other\n    discover: true\n",
     "bad.yaml:4: interface 'can0' is used by two buses (the service owns each bus alone)"},
    {"buses:\n  - interface: can0\n    discover: true\n  - interface: can1\n    name: can0\n    discover: true\n",
     "bad.yaml:4: bus name 'can0' appears twice"},
    {"log_level: loud\nbuses:\n  - interface: can0\n    discover: true\n",
     "bad.yaml:1: log_level 'loud' is not one of trace, debug, info, warn, error, critical, off"},
    {"timeouts:\n  stale_periods: 5\n  offline_periods: 4\nbuses:\n  - interface: can0\n    discover: true\n",
     "bad.yaml:3: offline_periods must be greater than stale_periods"},
    {"dds_transport: tcp\nbuses:\n  - interface: can0\n    discover: true\n",
     "bad.yaml:1: dds_transport 'tcp' is not one of default, udp, shm"},
    {"timeouts:\n  reply: 0\nbuses:\n  - interface: can0\n    discover: true\n",
     "bad.yaml:2: reply 0 out of range 0.01..10"},
    {"buses:\n  - interface: can0\n    discover: true\nsecurity:\n",
     "bad.yaml:4: security must be a mapping of the six files (see deploy/security/README.md)"},
    {"buses:\n  - interface: can0\n    discover: true\nsecurity:\n  identity_ca: a.pem\n  identity_cert: b.pem\n",
     "bad.yaml:6: unknown key 'identity_cert' in security (known: identity_ca, identity_certificate, private_key, "
     "permissions_ca, governance, permissions, warn_days)"},
    {"buses:\n  - interface: can0\n    discover: true\nsecurity:\n  identity_ca: a.pem\n  private_key: k.pem\n",
     "bad.yaml:4: security needs all six files: identity_certificate, permissions_ca, governance, permissions missing "
     "(or remove the section to run without security)"},
    {"buses:\n  - interface: can0\n    discover: true\nsecurity:\n  identity_ca: a\n  identity_certificate: b\n"
     "  private_key: c\n  permissions_ca: d\n  governance: ''\n  permissions: f\n",
     "bad.yaml:9: governance must be a path to a file, not empty"},
    {"buses:\n  - interface: can0\n    discover: true\nsecurity:\n  identity_ca: a\n  identity_certificate: b\n"
     "  private_key: c\n  permissions_ca: d\n  governance: e\n  permissions: [f]\n",
     "bad.yaml:10: permissions must be a path"},
    {"buses:\n  - interface: can0\n    discover: true\nsecurity:\n  identity_ca: a\n  identity_certificate: b\n"
     "  private_key: c\n  permissions_ca: d\n  governance: e\n  permissions: f\n  warn_days: -1\n",
     "bad.yaml:11: warn_days -1 out of range 0..3650"},
};

TEST(Config, EveryBadValueIsRefusedWithItsLine) {
  for (const auto& c : kBad) expect_refused(c.yaml, c.message);
}

TEST(Config, BatteryCapacityIsOptionalAndMoreThanZeroAh) {
  struct Good {
    const char* value;
    std::optional<double> ah;
  };
  const Good good[] = {{nullptr, std::nullopt}, {"20", 20.0}, {"0.5", 0.5}, {"10000", 10000.0}};
  for (const auto& g : good) {
    SCOPED_TRACE(g.value ? g.value : "absent");
    const std::string yaml = std::string("buses:\n  - interface: can0\n    batteries:\n      - node: 2\n") +
                             (g.value ? std::string("        capacity_ah: ") + g.value + "\n" : "");
    EXPECT_EQ(parse_config(yaml, "good.yaml").buses[0].batteries[0].capacity_ah, g.ah);
  }
  const std::string battery = "buses:\n  - interface: can0\n    batteries:\n      - node: 2\n        capacity_ah: ";
  const BadCase bad[] = {
      {"0\n", "bad.yaml:5: capacity_ah must be more than 0 Ah"},
      {"-20\n", "bad.yaml:5: capacity_ah -20 out of range 0..10000"},
      {"20000\n", "bad.yaml:5: capacity_ah 20000 out of range 0..10000"},
      {"20Ah\n", "bad.yaml:5: capacity_ah must be a number, not '20Ah'"},
      {".nan\n", "bad.yaml:5: capacity_ah .nan out of range 0..10000"},
      {"[20]\n", "bad.yaml:5: capacity_ah must be a number"},
  };
  for (const auto& b : bad) expect_refused(battery + b.yaml, b.message);
}

// discovery: and interfaces: (interface.md 7.2). Each case is appended to a valid bus
// section of three lines, so the first line of a case is line 4.
const char* const kBus = "buses:\n  - interface: can0\n    discover: true\n";

const BadCase kBadNetwork[] = {
    {"discovery: unicast\n",
     "bad.yaml:4: discovery must be a mapping: mode (multicast, unicast or server), peers, servers"},
    {"discovery:\n", "bad.yaml:4: discovery must be a mapping: mode (multicast, unicast or server), peers, servers"},
    {"discovery:\n  mode: broadcast\n",
     "bad.yaml:5: discovery mode 'broadcast' is not one of multicast, unicast, server"},
    {"discovery:\n  mode:\n  peers: [10.0.0.1]\n", "bad.yaml:5: discovery mode must be multicast, unicast or server"},
    {"discovery:\n  mode: [unicast]\n", "bad.yaml:5: discovery mode must be multicast, unicast or server"},
    {"discovery:\n  mode: unicast\n  peer: [10.0.0.1]\n",
     "bad.yaml:6: unknown key 'peer' in discovery (known: mode, peers, servers)"},
    {"discovery:\n  mode: unicast\n",
     "bad.yaml:5: discovery mode unicast needs peers: a list of IPv4 addresses or host names, each with an optional "
     ":PORT"},
    {"discovery:\n  peers: [10.0.0.1]\n",
     "bad.yaml:5: peers are for discovery mode unicast, not multicast (set mode: unicast, or remove peers)"},
    {"discovery:\n  mode: multicast\n  peers: [10.0.0.1]\n",
     "bad.yaml:6: peers are for discovery mode unicast, not multicast (set mode: unicast, or remove peers)"},
    {"discovery:\n  mode: server\n  servers: [10.0.0.1]\n  peers: [10.0.0.2]\n",
     "bad.yaml:7: peers are for discovery mode unicast, not server (set mode: unicast, or remove peers)"},
    {"discovery:\n  mode: unicast\n  servers: [10.0.0.1]\n",
     "bad.yaml:6: servers are for discovery mode server, not unicast (set mode: server, or remove servers)"},
    {"discovery:\n  mode: server\n",
     "bad.yaml:5: discovery mode server needs servers: the Discovery Servers' ADDRESS[:PORT] (port 11811 if none), in "
     "server id order"},
    {"discovery:\n  mode: unicast\n  peers: []\n",
     "bad.yaml:6: peers must name at least one peer, e.g. [192.168.10.2, "
     "\"10.0.0.7:7412\", gcs.local]"},
    {"discovery:\n  mode: unicast\n  peers:\n",
     "bad.yaml:6: peers must be a list, e.g. [192.168.10.2, \"10.0.0.7:7412\", gcs.local]"},
    {"discovery:\n  mode: unicast\n  peers: 10.0.0.1\n",
     "bad.yaml:6: peers must be a list, e.g. [192.168.10.2, \"10.0.0.7:7412\", gcs.local]"},
    {"discovery:\n  mode: unicast\n  peers:\n    - {host: 10.0.0.1}\n",
     "bad.yaml:7: peer must be a single address, e.g. [192.168.10.2, \"10.0.0.7:7412\", gcs.local]"},
    {"discovery:\n  mode: unicast\n  peers: [10.0.0.256]\n",
     "bad.yaml:6: peer '10.0.0.256': '10.0.0.256' is not an IPv4 address (four numbers 0..255: 192.168.10.2)"},
    {"discovery:\n  mode: unicast\n  peers: [10.0.1]\n",
     "bad.yaml:6: peer '10.0.1': '10.0.1' is not an IPv4 address (four numbers 0..255: 192.168.10.2)"},
    {"discovery:\n  mode: unicast\n  peers: [010.0.0.1]\n",
     "bad.yaml:6: peer '010.0.0.1': '010.0.0.1' is not an IPv4 address (four numbers 0..255: 192.168.10.2)"},
    {"discovery:\n  mode: unicast\n  peers: [\"10.0.0.1:0\"]\n",
     "bad.yaml:6: peer '10.0.0.1:0': port 0 out of range 1..65535"},
    {"discovery:\n  mode: unicast\n  peers: [\"10.0.0.1:65536\"]\n",
     "bad.yaml:6: peer '10.0.0.1:65536': port 65536 out of range 1..65535"},
    {"discovery:\n  mode: unicast\n  peers: [\"10.0.0.1:99999999999999999999\"]\n",
     "bad.yaml:6: peer '10.0.0.1:99999999999999999999': port 99999999999999999999 out of range 1..65535"},
    {"discovery:\n  mode: unicast\n  peers: [\"10.0.0.1:-1\"]\n",
     "bad.yaml:6: peer '10.0.0.1:-1': port '-1' is not a number"},
    {"discovery:\n  mode: unicast\n  peers: [\"10.0.0.1:\"]\n", "bad.yaml:6: peer '10.0.0.1:': no port after the ':'"},
    {"discovery:\n  mode: unicast\n  peers: [\":7412\"]\n", "bad.yaml:6: peer ':7412': no address before the ':'"},
    {"discovery:\n  mode: unicast\n  peers: [bad_host]\n",
     "bad.yaml:6: peer 'bad_host': 'bad_host' is not an IPv4 address or a host name (letters, digits, '-' and '.')"},
    {"discovery:\n  mode: unicast\n  peers: [-gcs.local]\n",
     "bad.yaml:6: peer '-gcs.local': '-gcs.local' is not an IPv4 address or a host name (letters, digits, '-' and "
     "'.')"},
    {"discovery:\n  mode: unicast\n  peers: [\"[::1]:7412\"]\n",
     "bad.yaml:6: peer '[::1]:7412': IPv6 is not supported (Fast DDS's UDPv4 transport carries DDS here): give an IPv4 "
     "address or a host name"},
    {"discovery:\n  mode: unicast\n  peers: [239.255.0.1]\n",
     "bad.yaml:6: peer '239.255.0.1': '239.255.0.1' is a multicast address, not a host's"},
    {"discovery:\n  mode: unicast\n  peers: [0.0.0.0]\n",
     "bad.yaml:6: peer '0.0.0.0': '0.0.0.0' is not a host's address"},
    {"discovery:\n  mode: unicast\n  peers: [255.255.255.255]\n",
     "bad.yaml:6: peer '255.255.255.255': '255.255.255.255' is the broadcast address"},
    {"discovery:\n  mode: unicast\n  peers:\n    - 10.0.0.1\n    - \"10.0.0.1:7412\"\n    - 10.0.0.1\n",
     "bad.yaml:9: peer '10.0.0.1' appears twice in peers"},
    {"discovery:\n  mode: unicast\n  peers: [GCS.local, gcs.local]\n",
     "bad.yaml:6: peer 'gcs.local' appears twice in peers"},
    {"discovery:\n  mode: server\n  servers: [\"10.0.0.1:11811\", \"10.0.0.1:11811\"]\n",
     "bad.yaml:6: server '10.0.0.1:11811' appears twice in servers"},
    {"discovery:\n  mode: server\n  servers: [\"\", \"\"]\n",
     "bad.yaml:6: servers must name at least one server (an empty entry only leaves its id unused), e.g. "
     "[\"10.0.0.1:11811\"]"},
    {"discovery:\n  mode: server\n  servers: [\"10.0.0.1:0\"]\n",
     "bad.yaml:6: server '10.0.0.1:0': port 0 out of range 1..65535"},
    {"dds_transport: shm\ndiscovery:\n  mode: unicast\n  peers: [10.0.0.1]\n",
     "bad.yaml:6: discovery mode unicast reaches other hosts over UDP, but dds_transport is shm (shared memory only): "
     "set dds_transport to udp or default"},
    {"interfaces: []\n", "bad.yaml:4: interfaces must name at least one interface, e.g. [eth1, 192.168.10.1]"},
    {"interfaces:\n", "bad.yaml:4: interfaces must be a list, e.g. [eth1, 192.168.10.1]"},
    {"interfaces: eth1\n", "bad.yaml:4: interfaces must be a list, e.g. [eth1, 192.168.10.1]"},
    {"interfaces: [eth1/2]\n",
     "bad.yaml:4: interface 'eth1/2': 'eth1/2' is not an interface name (1..15 characters, no '/', ':' or space) or an "
     "IPv4 address"},
    {"interfaces: [\"eth0:1\"]\n",
     "bad.yaml:4: interface 'eth0:1': 'eth0:1' is not an interface name (1..15 characters, no '/', ':' or space) or an "
     "IPv4 address"},
    {"interfaces: [averyveryverylongname]\n",
     "bad.yaml:4: interface 'averyveryverylongname': 'averyveryverylongname' is not an interface name (1..15 "
     "characters, no '/', ':' or space) or an IPv4 address"},
    {"interfaces: [192.168.1]\n",
     "bad.yaml:4: interface '192.168.1': '192.168.1' is not an IPv4 address (four numbers 0..255)"},
    {"interfaces: [0.0.0.0]\n", "bad.yaml:4: interface '0.0.0.0': '0.0.0.0' is not a host's address"},
    {"interfaces:\n  - eth1\n  - 192.168.10.1\n  - eth1\n", "bad.yaml:7: interface 'eth1' appears twice in interfaces"},
    {"dds_transport: shm\ninterfaces: [eth1]\n",
     "bad.yaml:5: interfaces restrict DDS over UDP, but dds_transport is shm (shared memory only, no network): set "
     "dds_transport to udp or default, or remove interfaces"},
};

TEST(ConfigNetwork, EveryBadValueIsRefusedWithItsLine) {
  for (const auto& c : kBadNetwork) expect_refused(std::string(kBus) + c.yaml, c.message);
}

TEST(ConfigNetwork, DiscoveryServerWithSecurityIsRefusedAtTheModeLine) {
  const std::string security =
      "security:\n  identity_ca: a\n  identity_certificate: b\n  private_key: c\n  permissions_ca: d\n"
      "  governance: e\n  permissions: f\n";
  const std::string server = "discovery:\n  mode: server\n  servers: [10.0.0.1]\n";
  for (const std::string& yaml : {std::string(kBus) + security + server, std::string(kBus) + server + security}) {
    SCOPED_TRACE(yaml);
    try {
      (void)parse_config(yaml, "bad.yaml");
      ADD_FAILURE() << "accepted";
    } catch (const ConfigError& e) {
      const std::string line = yaml.find("security") < yaml.find("discovery") ? "12" : "5";
      EXPECT_EQ(std::string(e.what()),
                "bad.yaml:" + line +
                    ": discovery mode server cannot be combined with DDS-Security in Fast DDS 2.9.1: secure "
                    "participants find nothing through a Discovery Server (an unauthenticated server is ignored, "
                    "and a secure one loses the GUID prefix its id gives it); use unicast peers");
    }
  }
  // Unicast peers and DDS-Security go together.
  EXPECT_EQ(parse_config(std::string(kBus) + security + "discovery:\n  mode: unicast\n  peers: [10.0.0.1]\n", "ok.yaml")
                .network.mode,
            dds::DiscoveryMode::Unicast);
}

TEST(ConfigNetwork, AbsentKeysMeanMulticastOnEveryInterfaceAsBefore) {
  const Config c = parse_config(kGood, "good.yaml");
  EXPECT_EQ(c.network.mode, dds::DiscoveryMode::Multicast);
  EXPECT_TRUE(c.network.peers.empty());
  EXPECT_TRUE(c.network.servers.empty());
  EXPECT_TRUE(c.network.interfaces.empty());
  EXPECT_EQ(parse_config(std::string(kBus) + "discovery:\n  mode: multicast\n", "m.yaml").network.mode,
            dds::DiscoveryMode::Multicast);
}

TEST(ConfigNetwork, UnicastPeersWithAndWithoutPortsAndTheirLines) {
  const Config c = parse_config(std::string(kBus) +
                                    "discovery:\n  mode: unicast\n  peers: [192.168.10.2, \"10.0.0.7:7412\", gcs.local,"
                                    " 10.0.0.7:7413]\ninterfaces:\n  - eth1\n  - 192.168.10.1\n",
                                "/etc/pmu-dds/pmu-service.yaml");
  const auto& n = c.network;
  EXPECT_EQ(n.mode, dds::DiscoveryMode::Unicast);
  ASSERT_EQ(n.peers.size(), 4u);
  EXPECT_EQ(n.peers[0].host, "192.168.10.2");
  EXPECT_EQ(n.peers[0].port, 0);
  EXPECT_EQ(n.peers[1].host, "10.0.0.7");
  EXPECT_EQ(n.peers[1].port, 7412);
  EXPECT_EQ(n.peers[2].host, "gcs.local");
  EXPECT_EQ(n.peers[3].port, 7413) << "unquoted HOST:PORT in a flow list is one string for yaml-cpp";
  EXPECT_EQ(n.peers[1].text, "10.0.0.7:7412");
  EXPECT_EQ(n.peers[1].where, "/etc/pmu-dds/pmu-service.yaml:6");
  ASSERT_EQ(n.interfaces.size(), 2u);
  EXPECT_EQ(n.interfaces[0].host, "eth1");
  EXPECT_EQ(n.interfaces[1].host, "192.168.10.1");
  EXPECT_EQ(n.interfaces[1].where, "/etc/pmu-dds/pmu-service.yaml:9");
}

TEST(ConfigNetwork, ServersInIdOrder) {
  const Config c = parse_config(std::string(kBus) +
                                    "discovery:\n  mode: server\n  servers:\n    - \"10.0.0.1:11811\"\n"
                                    "    - ds2.local\n",
                                "s.yaml");
  ASSERT_EQ(c.network.servers.size(), 2u);
  EXPECT_EQ(c.network.mode, dds::DiscoveryMode::Server);
  EXPECT_EQ(c.network.servers[0].host, "10.0.0.1");
  EXPECT_EQ(c.network.servers[0].port, 11811);
  EXPECT_EQ(c.network.servers[1].host, "ds2.local");
  EXPECT_EQ(c.network.servers[1].port, 0) << "11811 is filled in when resolved";
  EXPECT_EQ(c.network.servers[1].where, "s.yaml:8");
}

// A client of the server with id 1 alone (a Discovery Server on each mission computer, the
// ground station a client of all of them in id order).
TEST(ConfigNetwork, AnEmptyServerEntryLeavesItsIdUnused) {
  const Config c =
      parse_config(std::string(kBus) + "discovery:\n  mode: server\n  servers: [\"\", \"10.0.0.2\"]\n", "s.yaml");
  ASSERT_EQ(c.network.servers.size(), 2u);
  EXPECT_EQ(c.network.servers[0].host, "");
  EXPECT_EQ(c.network.servers[1].host, "10.0.0.2");
}

TEST(ConfigNetwork, AtMost256ServersTheIdsOfAGuidPrefixByte) {
  std::string yaml = std::string(kBus) + "discovery:\n  mode: server\n  servers:\n";
  for (int i = 0; i < 257; ++i)
    yaml += "    - \"10.0." + std::to_string(i / 200) + "." + std::to_string(i % 200 + 1) + "\"\n";
  try {
    (void)parse_config(yaml, "s.yaml");
    ADD_FAILURE() << "accepted";
  } catch (const ConfigError& e) {
    // Servers start on line 7; the 257th (index 256) is on line 263.
    EXPECT_EQ(std::string(e.what()), "s.yaml:263: more than 256 servers (server ids are 0..255)");
  }
}

// Devices 1..n on two buses (can0 holds the first half), one `- address:` line each.
std::string many_devices(int n) {
  std::string y = "buses:\n";
  for (int bus = 0; bus < 2; ++bus) {
    y += "  - interface: can" + std::to_string(bus) + "\n    devices:\n";
    const int first = bus == 0 ? 1 : n / 2 + 1, last = bus == 0 ? n / 2 : n;
    for (int a = first; a <= last; ++a) y += "      - address: " + std::to_string(a) + "\n";
  }
  return y;
}

TEST(Config, AsManyDevicesAsTheDdsWritersHoldAreAccepted) {
  const Config c = parse_config(many_devices(static_cast<int>(dds::kMaxDevicesPerService)), "fleet.yaml");
  ASSERT_EQ(c.buses.size(), 2u);
  EXPECT_EQ(c.buses[0].devices.size() + c.buses[1].devices.size(), dds::kMaxDevicesPerService);
}

TEST(Config, MoreDevicesThanTheDdsWritersHoldAreRefusedAtTheFirstOneTooMany) {
  // 257 devices: can0 has 1..128 (lines 4..131), can1 header lines 132-133, then 129..257;
  // the 257th is on line 133 + 129 = 262.
  try {
    (void)parse_config(many_devices(static_cast<int>(dds::kMaxDevicesPerService) + 1), "fleet.yaml");
    ADD_FAILURE() << "accepted";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()),
              "fleet.yaml:262: more than 256 devices in one service (the capacity its DDS writers are sized for, "
              "pmu::dds::kMaxDevicesPerService); split them across services");
  }
}

TEST(Config, BatteriesAndMpptsCountTowardsTheDevicesTheDdsWritersHold) {
  // 255 PMUs leave room for one more pmu/health instance: a battery fits, a battery and an
  // MPPT do not. can0 holds 1..127 (lines 4..130), can1 128..255 (lines 133..260), then
  // `batteries:` (261) and its list (262).
  const std::string pmus = many_devices(static_cast<int>(dds::kMaxDevicesPerService) - 1);
  const Config c = parse_config(pmus + "    batteries:\n      - node: 2\n", "fleet.yaml");
  EXPECT_EQ(c.buses[1].batteries.size(), 1u);
  try {
    (void)parse_config(pmus + "    batteries:\n      - node: 2\n    mppts:\n      - device: 0\n", "fleet.yaml");
    ADD_FAILURE() << "accepted";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()),
              "fleet.yaml:262: more than 256 devices (PMUs, batteries and MPPTs) in one service (the capacity its DDS "
              "writers are sized for, pmu::dds::kMaxDevicesPerService); split them across services");
  }
}

TEST(Config, SecuritySectionAllSixFilesRelativeToTheConfigFile) {
  const char* yaml = R"(buses:
  - interface: can0
    discover: true
security:
  identity_ca: /etc/pmu-dds/security/identity_ca.pem
  identity_certificate: pmu-service/cert.pem
  private_key: pmu-service/key.pem
  permissions_ca: /etc/pmu-dds/security/permissions_ca.pem
  governance: /etc/pmu-dds/security/governance.p7s
  permissions: pmu-service/permissions.p7s
  warn_days: 14
)";
  const Config c = parse_config(yaml, "/etc/pmu-dds/pmu-service.yaml");
  const auto& f = c.security.files;
  EXPECT_EQ(f.identity_ca, "/etc/pmu-dds/security/identity_ca.pem");
  EXPECT_EQ(f.identity_certificate, "/etc/pmu-dds/pmu-service/cert.pem");
  EXPECT_EQ(f.private_key, "/etc/pmu-dds/pmu-service/key.pem");
  EXPECT_EQ(f.permissions_ca, "/etc/pmu-dds/security/permissions_ca.pem");
  EXPECT_EQ(f.governance, "/etc/pmu-dds/security/governance.p7s");
  EXPECT_EQ(f.permissions, "/etc/pmu-dds/pmu-service/permissions.p7s");
  EXPECT_EQ(c.security.warn_days, 14);
  EXPECT_EQ(c.security.source_line, "/etc/pmu-dds/pmu-service.yaml:4");
  EXPECT_EQ(c.security.line_of("private_key"), "/etc/pmu-dds/pmu-service.yaml:7");
  EXPECT_EQ(c.security.line_of("something else"), "/etc/pmu-dds/pmu-service.yaml:4");
  // Without the section: no security, as before.
  EXPECT_TRUE(parse_config(kGood, "good.yaml").security.files.empty());
  EXPECT_EQ(parse_config(kGood, "good.yaml").security.warn_days, 30);
}

// A root-only key reaches the service's transient user as a systemd credential.
TEST(Config, SecurityFileFromASystemdCredential) {
  const auto yaml = [](const std::string& key_path) {
    return "buses:\n  - interface: can0\n    discover: true\nsecurity:\n  identity_ca: ca.pem\n"
           "  identity_certificate: cert.pem\n  private_key: " +
           key_path + "\n  permissions_ca: pca.pem\n  governance: gov.p7s\n  permissions: perm.p7s\n";
  };
  ConfigEnvironment systemd;
  systemd.credentials_directory = "/run/credentials/pmu-service.service";
  const Config c = parse_config(yaml("credential:pmu-service-key.pem"), "/etc/pmu-dds/pmu-service.yaml", systemd);
  EXPECT_EQ(c.security.files.private_key, "/run/credentials/pmu-service.service/pmu-service-key.pem");
  EXPECT_EQ(c.security.files.identity_certificate, "/etc/pmu-dds/cert.pem") << "other paths as before";

  const struct {
    std::string path;
    ConfigEnvironment env;
    std::string error;
  } bad[] = {
      {"credential:k.pem",
       {},
       "a.yaml:7: private_key: credential:k.pem needs $CREDENTIALS_DIRECTORY, which is not set: the service was not "
       "started by systemd with LoadCredential=k.pem:PATH (deploy/security/README.md)"},
      {"'credential:'", systemd,
       "a.yaml:7: private_key: '' is not a credential name (credential:NAME, NAME as in LoadCredential=NAME:PATH, "
       "no '/')"},
      {"credential:../key.pem", systemd,
       "a.yaml:7: private_key: '../key.pem' is not a credential name (credential:NAME, NAME as in "
       "LoadCredential=NAME:PATH, no '/')"},
  };
  for (const auto& b : bad) {
    SCOPED_TRACE(b.path);
    try {
      (void)parse_config(yaml(b.path), "a.yaml", b.env);
      ADD_FAILURE() << "accepted";
    } catch (const ConfigError& e) {
      EXPECT_EQ(std::string(e.what()), b.error);
    }
  }
}

TEST(Config, VehicleIsTheUnnamedOneUnlessNamed) {
  EXPECT_EQ(parse_config("buses:\n  - interface: sim\n    discover: true\n", "a.yaml").vehicle, "");
  EXPECT_EQ(parse_config("vehicle:\nbuses:\n  - interface: sim\n    discover: true\n", "a.yaml").vehicle, "");
  EXPECT_EQ(parse_config("vehicle: UAV-7.b_2\nbuses:\n  - interface: sim\n    discover: true\n", "a.yaml").vehicle,
            "UAV-7.b_2");
}

// The system's reason, in words: a missing file and an unreadable one are fixed differently.
TEST(ConfigFile, MissingFileSaysWhy) {
  try {
    (void)load_config("/nonexistent/pmu.yaml");
    ADD_FAILURE() << "accepted";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()), "/nonexistent/pmu.yaml: cannot read the config file: No such file or directory");
  }
}

TEST(ConfigFile, UnreadableFileSaysWhy) {
  if (::geteuid() == 0) GTEST_SKIP() << "root reads a file of mode 000: no EACCES to see";
  char path[] = "/tmp/pmu-config-XXXXXX";
  const int fd = ::mkstemp(path);
  ASSERT_GE(fd, 0);
  ::close(fd);
  ASSERT_EQ(::chmod(path, 0), 0);
  try {
    (void)load_config(path);
    ADD_FAILURE() << "accepted";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()), std::string(path) + ": cannot read the config file: Permission denied");
  }
  ::unlink(path);
}

TEST(ConfigFile, DirectoryIsNotAnEmptyFile) {
  try {
    (void)load_config("/tmp");
    ADD_FAILURE() << "accepted";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()), "/tmp: cannot read the config file: it is a directory, not a regular file");
  }
}

// Only a regular file within its bound is read (docs/safety.md H12): /dev/zero never ends, a
// FIFO's open waits for a writer that never comes; each is refused at once, saying why.
TEST(ConfigFile, ADeviceAFifoOrAHugeFileIsRefusedNotRead) {
  char dir[] = "/tmp/pmu-config-XXXXXX";
  ASSERT_NE(::mkdtemp(dir), nullptr);
  const std::string fifo = std::string(dir) + "/fifo.yaml";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const std::string huge = std::string(dir) + "/huge.yaml";
  {
    std::FILE* f = std::fopen(huge.c_str(), "w");
    ASSERT_NE(f, nullptr);
    const std::string line = "# " + std::string(1021, 'x') + "\n";  // 1 KiB a line
    for (int i = 0; i <= 1024; ++i) std::fputs(line.c_str(), f);
    std::fclose(f);
  }
  const std::pair<std::string, std::string> cases[] = {
      {"/dev/zero", "/dev/zero: cannot read the config file: it is a character device, not a regular file"},
      {fifo, fifo + ": cannot read the config file: it is a FIFO, not a regular file"},
      {huge, huge + ": cannot read the config file: it is 1025 KiB, larger than the 1 MiB bound"},
  };
  for (const auto& [path, message] : cases) {
    SCOPED_TRACE(path);
    try {
      (void)load_config(path);
      ADD_FAILURE() << "accepted";
    } catch (const ConfigError& e) {
      EXPECT_EQ(std::string(e.what()), message);
    }
  }
  ::unlink(fifo.c_str());
  ::unlink(huge.c_str());
  ::rmdir(dir);
}

// A key given twice, at any depth, is refused at its second line (yaml-cpp keeps both and
// n["key"] found the first, so the second was silently ignored); so is a second document.
const BadCase kRepeated[] = {
    {"buses:\n  - interface: can0\n    discover: true\nbuses:\n  - interface: can1\n    discover: true\n",
     "bad.yaml:4: key 'buses' appears twice in one mapping (first on line 1); give each key once"},
    {"domain: 1\nbuses:\n  - interface: can0\n    discover: true\ndomain: 2\n",
     "bad.yaml:5: key 'domain' appears twice in one mapping (first on line 1); give each key once"},
    {"vehicle: uav1\nvehicle: uav2\nbuses:\n  - interface: can0\n    discover: true\n",
     "bad.yaml:2: key 'vehicle' appears twice in one mapping (first on line 1); give each key once"},
    {"buses:\n  - interface: can0\n    interface: can1\n    discover: true\n",
     "bad.yaml:3: key 'interface' appears twice in one mapping (first on line 2); give each key once"},
    {"buses:\n  - interface: can0\n    devices:\n      - address: 1\n        address: 2\n",
     "bad.yaml:5: key 'address' appears twice in one mapping (first on line 4); give each key once"},
    {"timeouts:\n  reply: 0.3\n  reply: 0.5\nbuses:\n  - interface: can0\n    discover: true\n",
     "bad.yaml:3: key 'reply' appears twice in one mapping (first on line 2); give each key once"},
    {"discovery: {mode: unicast, peers: [10.0.0.1], mode: server}\nbuses:\n  - interface: can0\n    discover: true\n",
     "bad.yaml:1: key 'mode' appears twice in one mapping (first on line 1); give each key once"},
    {"? [a, b]\n: 1\nbuses:\n  - interface: can0\n    discover: true\n",
     "bad.yaml:1: a key must be a name, not a list or mapping"},
    {"buses:\n  - interface: can0\n    discover: true\n---\ndomain: 3\n",
     "bad.yaml:4: a second YAML document ('---'): the config is one document; merge it into the first"},
    {"buses:\n  - interface: can0\n    discover: true\n\n---\n",
     "bad.yaml:5: a second YAML document ('---'): the config is one document; merge it into the first"},
};

TEST(Config, RepeatedKeysAndSecondDocumentsAreRefusedAtTheirLine) {
  for (const auto& c : kRepeated) expect_refused(c.yaml, c.message);
  // One document may still say where it starts.
  EXPECT_EQ(parse_config("---\ndomain: 3\nbuses:\n  - interface: can0\n    discover: true\n", "a.yaml").domain, 3);
}

// Integers are plain decimal (interface.md 4.1): YAML 1.1 reads 010 as 8 and 0x10 as 16, so a
// PMU written 010 was PMU 8. Each form is refused at its line, naming the key.
TEST(Config, IntegersAreDecimalOnly) {
  const std::string rule =
      " must be a decimal integer (digits, optionally after '-'; no leading 0, '+', 0x, 0o, exponent or fraction), "
      "not ";
  for (const char* v : {"010", "0x10", "0o10", "1e1", "+5", "08", "1.0", "-05", "1_000", "00"}) {
    SCOPED_TRACE(v);
    expect_refused("buses:\n  - interface: can0\n    devices:\n      - address: " + std::string(v) + "\n",
                   "bad.yaml:4: address" + rule + "'" + v + "'");
  }
  expect_refused("domain: 010\nbuses:\n  - interface: can0\n    discover: true\n",
                 "bad.yaml:1: domain" + rule + "'010'");
  expect_refused("buses:\n  - interface: can0\n    mppts:\n      - device: 0x1\n",
                 "bad.yaml:4: device" + rule + "'0x1'");
  expect_refused("buses:\n  - interface: can0\n    bitrate: 5e5\n    discover: true\n",
                 "bad.yaml:3: bitrate" + rule + "'5e5'");
  // Accepted: 0, and decimal as written (quoted too); a negative one is out of range, not misread.
  for (const char* v : {"0", "8", "10", "65534", "\"10\""}) {
    SCOPED_TRACE(v);
    const Config c =
        parse_config("buses:\n  - interface: can0\n    devices:\n      - address: " + std::string(v) + "\n", "a.yaml");
    EXPECT_EQ(c.buses[0].devices[0].address, std::stoi(std::string(v[0] == '"' ? v + 1 : v)));
  }
  expect_refused("buses:\n  - interface: can0\n    devices:\n      - address: -1\n",
                 "bad.yaml:4: address -1 out of range 0..65534");
  expect_refused("buses:\n  - interface: can0\n    devices:\n      - address: 99999999999999999999\n",
                 "bad.yaml:4: address must be an integer, not '99999999999999999999'");
}

// Names are limited in bytes (the IDL's string<15>), shown whole when short, else as a
// prefix cut at a character boundary with the length: never half a UTF-8 character, never a
// megabyte in a message.
TEST(Config, NameLimitsAreBytesAndLongValuesAreShownShort) {
  expect_refused(
      "buses:\n  - interface: can0\n    name: \xC3\xA9t\xC3\xA9-\xC3\xA9t\xC3\xA9-\xC3\xA9t\xC3\xA9\n    discover: true\n",
      "bad.yaml:3: bus name '\xC3\xA9t\xC3\xA9-\xC3\xA9t\xC3\xA9-\xC3\xA9t\xC3\xA9' must be 1..15 bytes (it is a "
      "DDS key, string<15>)");
  // 1 + 13 x 3 bytes: the 24-byte prefix holds 'a' and 7 euro signs; the 8th would be cut.
  std::string euros = "a";
  for (int i = 0; i < 13; ++i) euros += "\xE2\x82\xAC";
  std::string shown = "a";
  for (int i = 0; i < 7; ++i) shown += "\xE2\x82\xAC";
  expect_refused("buses:\n  - interface: can0\n    name: " + euros + "\n    discover: true\n",
                 "bad.yaml:3: bus name '" + shown +
                     "...' (40 bytes) must be 1..15 bytes (it is a DDS key, string<15>)");
  const std::string huge(1000000, 'v');
  expect_refused("vehicle: " + huge + "\nbuses:\n  - interface: can0\n    discover: true\n",
                 "bad.yaml:1: vehicle '" + std::string(24, 'v') +
                     "...' (1000000 bytes) is 1000000 bytes; a vehicle "
                     "name has at most 15 (it is a DDS key, string<15>)");
  expect_refused("log_level: " + huge + "\nbuses:\n  - interface: can0\n    discover: true\n",
                 "bad.yaml:1: log_level '" + std::string(24, 'v') +
                     "...' (1000000 bytes) is not one of trace, debug, "
                     "info, warn, error, critical, off");
  expect_refused(
      "vehicle: uav\xC3\xA9\nbuses:\n  - interface: can0\n    discover: true\n",
      "bad.yaml:1: vehicle 'uav\xC3\xA9' contains '\xC3\xA9'; a vehicle name is letters, digits, '_', '-' and "
      "'.' (it is also a DDS partition name, where other characters are patterns)");
  expect_refused("vehicle: \"uav\\t1\"\nbuses:\n  - interface: can0\n    discover: true\n",
                 "bad.yaml:1: vehicle 'uav\\x091' contains byte 0x09; a vehicle name is letters, digits, '_', '-' and "
                 "'.' (it is also a DDS partition name, where other characters are patterns)");
}

// qos_file: relative to the config file's folder, like the security files; its line is kept
// for the start-up check's messages.
TEST(Config, QosFileIsRelativeToTheConfigFolder) {
  const std::string bus = "buses:\n  - interface: can0\n    discover: true\n";
  const Config rel = parse_config("qos_file: site/qos.xml\n" + bus, "/etc/pmu-dds/pmu-service.yaml");
  EXPECT_EQ(rel.qos_file, "/etc/pmu-dds/site/qos.xml");
  EXPECT_EQ(rel.qos_file_line, "/etc/pmu-dds/pmu-service.yaml:1");
  EXPECT_EQ(parse_config(bus + "qos_file: /opt/qos.xml\n", "a.yaml").qos_file, "/opt/qos.xml");
  EXPECT_EQ(parse_config(bus, "a.yaml").qos_file, "") << "none: the installed one, found at start";
  expect_refused(bus + "qos_file: ''\n", "bad.yaml:4: qos_file must be a path to a file, not empty");
}

// dds_type_objects (interface.md 9.4): off unless true.
TEST(ConfigTypeObjects, OffUnlessTrueAndRefusedAtItsLineWhenNotABoolean) {
  EXPECT_FALSE(parse_config(kBus, "s.yaml").dds_type_objects);
  EXPECT_TRUE(parse_config(std::string("dds_type_objects: true\n") + kBus, "s.yaml").dds_type_objects);
  EXPECT_FALSE(parse_config(std::string("dds_type_objects: false\n") + kBus, "s.yaml").dds_type_objects);
  const BadCase bad[] = {
      {"domain: 3\ndds_type_objects: all\n", "bad.yaml:2: dds_type_objects must be true or false, not 'all'"},
      {"dds_type_objects: [true]\n", "bad.yaml:1: dds_type_objects must be true or false"},
  };
  for (const auto& c : bad) expect_refused(c.yaml + std::string(kBus), c.message);
}

// link (interface.md 4): the link to the ground, a profile and/or its round trip, which set
// the participant's announcements and how often the reliable writers may heartbeat; unset by
// default (Fast DDS's and qos.xml's periods).
TEST(ConfigLink, RoundTripInSecondsOrUnset) {
  EXPECT_FALSE(parse_config(kBus, "s.yaml").network.link.round_trip);
  const auto c = parse_config(std::string("link:\n  round_trip: 0.6\n") + kBus, "s.yaml");
  ASSERT_TRUE(c.network.link.round_trip);
  EXPECT_EQ(*c.network.link.round_trip, std::chrono::milliseconds(600));
  EXPECT_EQ(c.network.link.round_trip_where, "s.yaml:2");
  EXPECT_EQ(*parse_config(std::string("link: {round_trip: 2}\n") + kBus, "s.yaml").network.link.round_trip,
            std::chrono::milliseconds(2000));
  const BadCase bad[] = {
      {"link: 0.6\n", "bad.yaml:1: link must be a map: {profile: radio} and/or {round_trip: SECONDS}"},
      {"domain: 3\nlink: {}\n",
       "bad.yaml:2: link needs profile (radio, none) or round_trip: the link's round trip in seconds, 0.001..30"},
      {"link:\n  round_trip: 31\n", "bad.yaml:2: link round_trip 31 out of range 0..30"},
      {"link:\n  round_trip: 0\n", "bad.yaml:2: link round_trip 0 is below 0.001 s"},
      {"link:\n  round_trip: fast\n", "bad.yaml:2: link round_trip must be a number, not 'fast'"},
      {"link:\n  rtt: 0.6\n", "bad.yaml:2: unknown key 'rtt' in link (known: profile, round_trip)"},
      {"domain: 1\nlink:\n  profile: satellite\n", "bad.yaml:3: link profile 'satellite' is not one of: radio, none"},
      {"link: {profile: Radio}\n", "bad.yaml:1: link profile 'Radio' is not one of: radio, none"},
      {"link:\n  profile: [radio]\n", "bad.yaml:2: link profile must be radio or none"},
  };
  for (const auto& b : bad) expect_refused(b.yaml + std::string(kBus), b.message);
}

// link profile (interface.md 4, 7.3): one line gives every value a radio link needs, each
// with where it came from; round_trip overrides the profile's round trip.
TEST(ConfigLink, ProfileRadioSetsItsBundleAndRoundTripOverridesIt) {
  struct Case {
    const char* yaml;
    long round_trip_ms, heartbeat_ms, announcement_ms, lease_ms;
    int initial;
    bool low_rate;
    const char* round_trip_from;
    long low_rate_period_ms;  // the service's, after the profile
  };
  const Case cases[] = {
      {"", 0, 0, 0, 0, 0, false, "", 1000},
      {"link: {profile: none}\n", 0, 0, 0, 0, 0, false, "", 1000},
      {"link: {round_trip: 0.6}\n", 600, 900, 0, 0, 0, false, "round_trip, s.yaml:1", 1000},
      {"link: {profile: radio}\n", 700, 1050, 20000, 60000, 1, true, "profile radio, s.yaml:1", 2000},
      {"link:\n  profile: radio\n  round_trip: 1.2\n", 1200, 1800, 20000, 60000, 1, true, "round_trip, s.yaml:3", 2000},
      // The config's own low_rate_period wins over the profile's, before or after link:.
      {"low_rate_period: 1\nlink: {profile: radio}\n", 700, 1050, 20000, 60000, 1, true, "profile radio, s.yaml:2",
       1000},
      {"link: {profile: radio}\nlow_rate_period: 0.5\n", 700, 1050, 20000, 60000, 1, true, "profile radio, s.yaml:1",
       500},
      {"link: {profile: radio}\nlow_rate_period: 0\n", 700, 1050, 20000, 60000, 1, true, "profile radio, s.yaml:1", 0},
      {"low_rate_period: 5\n", 0, 0, 0, 0, 0, false, "", 5000},
  };
  for (const auto& k : cases) {
    SCOPED_TRACE(k.yaml);
    const auto c = parse_config(k.yaml + std::string(kBus), "s.yaml");
    const auto plan = pmu::dds::link_plan(c.network.link);
    EXPECT_EQ(plan.round_trip.value.count(), k.round_trip_ms);
    EXPECT_EQ(plan.round_trip.from, k.round_trip_from);
    EXPECT_EQ(plan.heartbeat_floor.value.count(), k.heartbeat_ms);
    EXPECT_EQ(plan.announcement_period.value.count(), k.announcement_ms);
    EXPECT_EQ(plan.lease.value.count(), k.lease_ms);
    EXPECT_EQ(plan.initial_announcements, k.initial);
    EXPECT_EQ(plan.low_rate_watch, k.low_rate);
    EXPECT_EQ(c.low_rate_period.count(), k.low_rate_period_ms);
  }
}

TEST(ConfigLink, ExplanationNamesEachValueAndItsOrigin) {
  const auto radio = pmu::dds::link_plan(
      parse_config(std::string("link:\n  profile: radio\n  round_trip: 0.5\n") + kBus, "s.yaml").network.link);
  const std::vector<std::string> expected = {
      "link: profile radio",
      "link: round trip 0.5 s (round_trip, s.yaml:3)",
      "link: reliable writers heartbeat every 0.75 s at most (1.5 round trips)",
      "link: participant announced every 20 s (profile radio, s.yaml:2)",
      "link: participant lease 60 s (profile radio, s.yaml:2)",
      "link: 1 initial announcement(s) (profile radio)",
      "link: the service writes the low-rate topics every 2 s unless its config sets low_rate_period (profile radio, "
      "s.yaml:2)",
      "link: pmuctl watch reads the low-rate topics pmu/low_rate/* (profile radio)",
      "link: pmuctl agent runs 1 worker(s) unless --workers (profile radio)",
  };
  EXPECT_EQ(radio.explain(), expected);
  EXPECT_EQ(pmu::dds::link_plan(parse_config(kBus, "s.yaml").network.link).explain(),
            std::vector<std::string>{"link: none (Fast DDS's discovery periods, qos.xml's heartbeat periods)"});
}

// also_serve_contract (interface.md 10.3): unset by default; only the contract before this
// build's, whose names the second participant writes and whose changed types it converts.
TEST(ConfigAlsoServeContract, UnsetByDefaultAndOnlyThePreviousMajorVersion) {
  EXPECT_FALSE(parse_config(kBus, "s.yaml").also_serve_contract);
  EXPECT_EQ(parse_config(std::string("also_serve_contract: 4\n") + kBus, "s.yaml").also_serve_contract, 4);
  const BadCase bad[] = {
      {"domain: 3\nalso_serve_contract: 3\n",
       "bad.yaml:2: also_serve_contract 3 is not served: this service serves contract 5 and can also serve 4 only "
       "(docs/interface.md section 10)"},
      {"also_serve_contract: 5\n",
       "bad.yaml:1: also_serve_contract 5 is not served: this service serves contract 5 and can also serve 4 only "
       "(docs/interface.md section 10)"},
      {"also_serve_contract: v3\n",
       "bad.yaml:1: also_serve_contract must be a decimal integer (digits, optionally after '-'; no leading 0, '+', 0x, "
       "0o, exponent or fraction), not 'v3'"},
  };
  for (const auto& c : bad) expect_refused(c.yaml + std::string(kBus), c.message);
}

// dds_statistics (interface.md 9.3): Fast DDS's statistics topic names, or all; Fast DDS
// itself would only log a wrong name, so the config refuses it at its line.
TEST(ConfigStatistics, OffUnlessNamedAllOrAList) {
  EXPECT_TRUE(parse_config(kBus, "s.yaml").dds_statistics.empty());
  EXPECT_TRUE(parse_config(std::string("dds_statistics: []\n") + kBus, "s.yaml").dds_statistics.empty());
  EXPECT_EQ(parse_config(std::string("dds_statistics: all\n") + kBus, "s.yaml").dds_statistics,
            dds::statistics_topic_names());
  EXPECT_EQ(dds::statistics_topic_names().size(), 17u) << "every topic of Fast DDS 2.9.1's topic_names.hpp";
  const Config c = parse_config(std::string("dds_statistics:\n  - _fastdds_statistics_history2history_latency\n"
                                            "  - _fastdds_statistics_physical_data\n") +
                                    kBus,
                                "s.yaml");
  EXPECT_EQ(c.dds_statistics, (std::vector<std::string>{"_fastdds_statistics_history2history_latency",
                                                        "_fastdds_statistics_physical_data"}));
  EXPECT_EQ(dds::statistics_property(c.dds_statistics),
            "_fastdds_statistics_history2history_latency;_fastdds_statistics_physical_data");
}

TEST(ConfigStatistics, UnknownOrRepeatedTopicIsRefusedAtItsLine) {
  const BadCase bad[] = {
      {"dds_statistics:\n  - _fastdds_statistics_history2history_latency\n  - history2history_latency\n",
       "bad.yaml:3: unknown statistics topic 'history2history_latency' (known: "
       "_fastdds_statistics_history2history_latency, _fastdds_statistics_network_latency, "
       "_fastdds_statistics_publication_throughput, _fastdds_statistics_subscription_throughput, "
       "_fastdds_statistics_rtps_sent, _fastdds_statistics_rtps_lost, _fastdds_statistics_resent_datas, "
       "_fastdds_statistics_heartbeat_count, _fastdds_statistics_acknack_count, _fastdds_statistics_nackfrag_count, "
       "_fastdds_statistics_gap_count, _fastdds_statistics_data_count, _fastdds_statistics_pdp_packets, "
       "_fastdds_statistics_edp_packets, _fastdds_statistics_discovered_entity, _fastdds_statistics_sample_datas, "
       "_fastdds_statistics_physical_data)"},
      {"dds_statistics: [_fastdds_statistics_rtps_sent, _fastdds_statistics_rtps_sent]\n",
       "bad.yaml:1: statistics topic '_fastdds_statistics_rtps_sent' appears twice in dds_statistics"},
      {"dds_statistics: yes\n",
       "bad.yaml:1: dds_statistics must be all or a list of statistics topic names, e.g. "
       "[_fastdds_statistics_history2history_latency]"},
      {"dds_statistics:\n",
       "bad.yaml:1: dds_statistics must be all or a list of statistics topic names (may be empty: [])"},
  };
  for (const auto& c : bad) expect_refused(c.yaml + std::string(kBus), c.message);
}

TEST(Config, BusOverride) {
  Config c = parse_config(kGood, "good.yaml");
  override_bus(c, "socketcan:vcan0");
  ASSERT_EQ(c.buses.size(), 1u);
  EXPECT_EQ(c.buses[0].interface, "vcan0");
  EXPECT_EQ(c.buses[0].name, "vcan0");
  EXPECT_EQ(c.buses[0].devices.size(), 2u) << "devices of the first bus are kept";
  override_bus(c, "sim");
  EXPECT_EQ(c.buses[0].interface, "sim");
  EXPECT_THROW(override_bus(c, "can0"), ConfigError);
  EXPECT_THROW(override_bus(c, "socketcan:"), ConfigError);
  EXPECT_EQ(c.dds_transport, dds::Transport::Default);
  EXPECT_EQ(
      parse_config("dds_transport: udp\nbuses:\n  - interface: can0\n    discover: true\n", "u.yaml").dds_transport,
      dds::Transport::UdpOnly);
  EXPECT_EQ(
      parse_config("dds_transport: shm\nbuses:\n  - interface: can0\n    discover: true\n", "s.yaml").dds_transport,
      dds::Transport::ShmOnly);
  override_bus(c, "fd:5");
  EXPECT_EQ(c.buses[0].interface, "fd:5");
  EXPECT_EQ(c.buses[0].name, "fd5");
  for (const char* bad : {"fd:", "fd:2", "fd:x", "fd:5x", "fd:-4"})
    EXPECT_THROW(override_bus(c, bad), ConfigError) << bad;
  const Config d = default_sim_config();
  ASSERT_EQ(d.buses.size(), 1u);
  EXPECT_EQ(d.buses[0].devices.at(0).address, 1);
}

}  // namespace
}  // namespace pmu::service
