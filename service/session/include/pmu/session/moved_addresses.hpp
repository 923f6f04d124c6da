#pragma once
// The PMUs that answer at another CAN address than the config file gives them, kept in the
// service's state directory so that `pmu-service --check-config` can tell a stale `address:`
// without the bus (docs/interface.md, "After a CAN address change").
//
// The file is `moved-addresses` in $STATE_DIRECTORY (systemd's StateDirectory=; its first
// entry), else in /var/lib/pmu-dds. One line per moved unit, '#' starts a comment:
//
//   # bus configured-address address-now serial
//   can0 1 7 1001
//
// (serial `-`: not read). A unit back at its configured address has no line. The service
// rewrites the whole file after every move (a new file renamed over the old, so a reader
// never sees half of one); at start it drops the lines of devices no longer in the config
// (the config was fixed) and logs the others.
//
// Parsing is total: every line gives a record or a "FILE:LINE: what" error.

#include <cstdint>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "pmu/config/config.hpp"

namespace pmu::service {

struct MovedAddress {
  std::string bus;
  std::uint16_t configured = 0;  // the config's `address:`
  std::uint16_t now = 0;         // where the unit answers
  std::optional<std::uint16_t> serial;
  std::string where;  // "FILE:LINE" of its line, when read from a file
};

// `state_directory`: $STATE_DIRECTORY as the environment has it (null: unset).
std::string moved_addresses_path(const char* state_directory);

struct MovedAddresses {
  std::vector<MovedAddress> moves;
  std::vector<std::string> errors;  // "FILE:LINE: what"; the line is skipped
};
MovedAddresses parse_moved_addresses(const std::string& text, const std::string& source);
std::string format_moved_addresses(const std::vector<MovedAddress>& moves);
// Reads `path`; a missing file is no moves. Errors say FILE:LINE, or FILE and why it cannot be read.
MovedAddresses read_moved_addresses(const std::string& path);

// One message per configured device that the records say answers elsewhere:
// "CONFIG:LINE: bus can0, address 1: the PMU (serial 1001) answers at address 7 (STATE:LINE):
// change `address: 1` to `address: 7`".
std::vector<std::string> stale_addresses(const Config& config, const std::vector<MovedAddress>& moves);

// The file as the running service keeps it. Thread-safe: every bus worker records its moves.
class MovedAddressStore {
 public:
  // Reads `path`, keeps the records of devices `config` still has (rewriting the file when it
  // drops any) and logs each stale address. Never throws: a file that cannot be read or
  // written is logged, and the service runs on.
  MovedAddressStore(std::string path, const Config& config);
  // A configured device moved (`first` its configured address, `to` where it is now).
  void record(const std::string& bus, std::uint16_t first, std::uint16_t to, std::optional<std::uint16_t> serial);
  std::vector<MovedAddress> moves() const;

 private:
  void write_locked();
  std::string path_;
  mutable std::mutex mutex_;
  std::vector<MovedAddress> moves_;
};

}  // namespace pmu::service
