#include "pmu/session/moved_addresses.hpp"

#include <spdlog/spdlog.h>

#include <cerrno>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <set>
#include <sstream>

#include "pmu/codec/ids.hpp"
#include "pmu/files/bounded_file.hpp"

namespace pmu::service {
namespace {

constexpr const char* kDefaultStateDirectory = "/var/lib/pmu-dds";
constexpr const char* kFileName = "moved-addresses";
// A line per moved PMU, under 40 bytes: far more than a service's PMUs ever fill.
constexpr std::size_t kMaxMovedAddressesBytes = std::size_t{64} << 10;

std::optional<std::uint16_t> number(const std::string& word, std::uint32_t max) {
  std::uint32_t v = 0;
  const auto r = std::from_chars(word.data(), word.data() + word.size(), v);
  if (word.empty() || r.ec != std::errc{} || r.ptr != word.data() + word.size() || v > max) return std::nullopt;
  return static_cast<std::uint16_t>(v);
}

std::string serial_text(const std::optional<std::uint16_t>& s) { return s ? std::to_string(*s) : "-"; }

}  // namespace

std::string moved_addresses_path(const char* state_directory) {
  std::string dir = state_directory != nullptr ? state_directory : "";
  dir = dir.substr(0, dir.find(':'));  // systemd lists one path per StateDirectory= entry
  if (dir.empty()) dir = kDefaultStateDirectory;
  if (dir.back() != '/') dir += '/';
  return dir + kFileName;
}

MovedAddresses parse_moved_addresses(const std::string& text, const std::string& source) {
  MovedAddresses out;
  std::istringstream in(text);
  std::string line;
  std::set<std::pair<std::string, std::uint16_t>> seen;
  for (int n = 1; std::getline(in, line); ++n) {
    const std::string where = source + ":" + std::to_string(n);
    line = line.substr(0, line.find('#'));
    std::istringstream words(line);
    std::vector<std::string> w;
    for (std::string word; words >> word;) w.push_back(word);
    if (w.empty()) continue;
    if (w.size() != 4) {
      out.errors.push_back(where + ": expected `BUS CONFIGURED-ADDRESS ADDRESS-NOW SERIAL`, got " +
                           std::to_string(w.size()) + " field(s)");
      continue;
    }
    MovedAddress m;
    m.bus = w[0];
    m.where = where;
    const auto configured = number(w[1], codec::kMaxDeviceAddress);
    const auto now = number(w[2], codec::kMaxDeviceAddress);
    const auto serial = w[3] == "-" ? std::optional<std::uint16_t>() : number(w[3], 0xFFFF);
    if (!configured || !now) {
      out.errors.push_back(where + ": address '" + (configured ? w[2] : w[1]) + "' is not 0.." +
                           std::to_string(codec::kMaxDeviceAddress));
      continue;
    }
    if (w[3] != "-" && !serial) {
      out.errors.push_back(where + ": serial '" + w[3] + "' is not 0..65535 or -");
      continue;
    }
    if (!seen.insert({m.bus, *configured}).second) {
      out.errors.push_back(where + ": bus " + m.bus + " address " + w[1] + " appears twice");
      continue;
    }
    m.configured = *configured;
    m.now = *now;
    m.serial = serial;
    out.moves.push_back(m);
  }
  return out;
}

std::string format_moved_addresses(const std::vector<MovedAddress>& moves) {
  std::string s =
      "# Written by pmu-service: PMUs that answer at another CAN address than the config gives them.\n"
      "# bus configured-address address-now serial\n";
  for (const auto& m : moves)
    s += m.bus + " " + std::to_string(m.configured) + " " + std::to_string(m.now) + " " + serial_text(m.serial) + "\n";
  return s;
}

MovedAddresses read_moved_addresses(const std::string& path) {
  // Bounded and regular: a state file replaced by a device or FIFO must not stop the start
  // (docs/safety.md H12); it is then reported and no moves are taken from it.
  const auto file = files::read_bounded_file(path, kMaxMovedAddressesBytes);
  if (!file.ok()) {
    if (file.system_error == ENOENT) return {};
    return {{}, {path + ": cannot read: " + file.error}};
  }
  return parse_moved_addresses(file.text, path);
}

std::vector<std::string> stale_addresses(const Config& config, const std::vector<MovedAddress>& moves) {
  std::vector<std::string> out;
  for (const auto& bus : config.buses)
    for (const auto& d : bus.devices)
      for (const auto& m : moves) {
        if (m.bus != bus.name || m.configured != d.address || m.now == d.address) continue;
        out.push_back((d.source_line.empty() ? config.source : d.source_line) + ": bus " + bus.name + ", address " +
                      std::to_string(d.address) + ": the PMU" +
                      (m.serial ? " (serial " + std::to_string(*m.serial) + ")" : std::string()) +
                      " answers at address " + std::to_string(m.now) + " (" + m.where + "): change `address: " +
                      std::to_string(d.address) + "` to `address: " + std::to_string(m.now) + "`");
      }
  return out;
}

MovedAddressStore::MovedAddressStore(std::string path, const Config& config) : path_(std::move(path)) {
  auto read = read_moved_addresses(path_);
  for (const auto& e : read.errors) spdlog::warn("{} (line ignored)", e);
  std::size_t dropped = 0;
  for (auto& m : read.moves) {
    bool configured = false;
    for (const auto& bus : config.buses)
      for (const auto& d : bus.devices) configured |= bus.name == m.bus && d.address == m.configured;
    if (configured)
      moves_.push_back(std::move(m));
    else
      ++dropped;
  }
  for (const auto& s : stale_addresses(config, moves_)) spdlog::warn("stale config: {}", s);
  if (dropped > 0 || !read.errors.empty()) {
    std::lock_guard<std::mutex> lock(mutex_);
    write_locked();
  }
}

void MovedAddressStore::record(const std::string& bus, std::uint16_t first, std::uint16_t to,
                               std::optional<std::uint16_t> serial) {
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = moves_.begin();
  while (it != moves_.end() && !(it->bus == bus && it->configured == first)) ++it;
  if (to == first) {
    if (it == moves_.end()) return;
    moves_.erase(it);
  } else if (it == moves_.end()) {
    moves_.push_back({bus, first, to, serial, {}});
  } else {
    it->now = to;
    it->serial = serial;
  }
  write_locked();
}

std::vector<MovedAddress> MovedAddressStore::moves() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return moves_;
}

void MovedAddressStore::write_locked() {
  // A new file renamed over the old: --check-config never reads half of one.
  const std::string tmp = path_ + ".new";
  {
    std::ofstream out(tmp, std::ios::trunc);
    out << format_moved_addresses(moves_);
    out.flush();
    if (!out) {
      spdlog::warn("cannot record moved CAN addresses in {}: {}; --check-config will not know of them", tmp,
                   std::strerror(errno));
      return;
    }
  }
  if (std::rename(tmp.c_str(), path_.c_str()) != 0)
    spdlog::warn("cannot record moved CAN addresses in {}: {}; --check-config will not know of them", path_,
                 std::strerror(errno));
}

}  // namespace pmu::service
