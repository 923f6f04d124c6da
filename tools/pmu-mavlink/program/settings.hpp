#pragma once
// pmu-mavlink's settings: the config file (YAML; errors as FILE:LINE: what) with the
// command line over it. Start-up only: read_settings_file throws SettingsError.
#include <chrono>
#include <cstdint>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>

#include "link/endpoint_address.hpp"
#include "pmu/mavlink/constants.hpp"
#include "pmu/mavlink/message_table.hpp"
#include "pmu/mavlink_params/confirm_set.hpp"

namespace pmu::mavlink_bridge {

class SettingsError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// MAV_COMP_ID_BATTERY (180): the devguide's battery service asks a battery that is its own
// component for this id and MAV_TYPE_BATTERY; most of what pmu-mavlink sends is battery
// state, and ground stations key a component's kind on its HEARTBEAT, not its id. The
// onboard-computer ids (191..194) are often taken by MAVROS or companion software, and
// MAV_COMP_ID_PERIPHERAL (158) is meant for devices without the parameter service.
inline constexpr std::uint8_t kDefaultComponentId = pmu::mavlink::mav_component::kBattery;

// Clear of the autopilot's own batteries (0 and 1, which ArduPilot and PX4 use): ground
// stations key batteries by id alone, whichever component sends them.
inline constexpr std::uint8_t kDefaultPmuBatteryId = 10;
inline constexpr std::uint8_t kDefaultBmsBatteryId = 20;

struct Settings {
  std::optional<UdpAddress> udp;
  std::optional<SerialAddress> serial;
  std::optional<std::uint8_t> system_id;  // none: the autopilot's, from its HEARTBEAT
  std::uint8_t component_id = kDefaultComponentId;
  int domain = 0;
  std::string vehicle;
  std::string qos_file;
  std::string security_dir;
  std::string identity;
  // The message-signing key file (signing/signing_key_file.hpp); empty: signing off.
  std::string signing_key;
  // PMU n (in the order first heard, from 0): battery A id pmu_battery_id + 2n, B + 2n + 1.
  std::uint8_t pmu_battery_id = kDefaultPmuBatteryId;
  // BMS n (in the order first heard): bms_battery_id + n.
  std::uint8_t bms_battery_id = kDefaultBmsBatteryId;
  // Message id -> interval; zero: not sent. HEARTBEAT 1 Hz (the devguide's rate),
  // BATTERY_STATUS 0.5 Hz per battery (the devguide's battery service), GENERATOR_STATUS 1 Hz,
  // RELAY_STATUS 1 Hz: a DO_SET_RELAY shows within a second for 19 bytes/s, 0.33 % of a
  // 57.6 kbit/s radio (bench/results/2026-12-06-mavlink-budget.md).
  std::map<std::uint32_t, std::chrono::microseconds> intervals{
      {pmu::mavlink::msgid::kHeartbeat, std::chrono::seconds(1)},
      {pmu::mavlink::msgid::kBatteryStatus, std::chrono::seconds(2)},
      {pmu::mavlink::msgid::kGeneratorStatus, std::chrono::seconds(1)},
      {pmu::mavlink::msgid::kRelayStatus, std::chrono::seconds(1)},
  };
  // The confirm rules (interface.md 2.2) whose commands and sets go to the service with
  // `confirm` (`confirm:` in the file and every --confirm RULE): the ground station's own
  // dialog is the confirmation. None by default: such a command is DENIED, naming its rule.
  pmu::mavlink_params::ConfirmSet confirm{};
};

// The config file's text into `into` (keys it does not set keep their value). `source`
// names the file in errors: "FILE:LINE: what".
void read_settings(const std::string& text, const std::string& source, Settings& into);

// --confirm RULE into `into` (added to the file's rules); the error when RULE is none.
std::optional<std::string> apply_confirm_option(const std::string& rule, Settings& into);

// The rate names of the config's `rates:` and of --rate NAME=HZ.
std::optional<std::uint32_t> rate_message(const std::string& name);
// "NAME=HZ" (HZ 0 = off, else 0.01..50) into `into`; the error when it is not one.
std::optional<std::string> apply_rate_option(const std::string& text, Settings& into);

}  // namespace pmu::mavlink_bridge
