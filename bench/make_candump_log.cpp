// make_candump_log N [--screen]: N lines of candump -L (or screen form) with the traffic mix
// of a PMU streaming every packet, plus gets, sets and replies, so decode benchmarks see
// every code path. Deterministic: the same N gives the same file.
#include <cinttypes>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "pmu/codec/encode.hpp"

using namespace pmu::codec;

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: make_candump_log N [--screen]\n");
    return 2;
  }
  const long n = std::strtol(argv[1], nullptr, 10);
  const bool screen = argc > 2 && std::strcmp(argv[2], "--screen") == 0;
  std::vector<CanFrame> mix;
  for (std::uint16_t addr : {std::uint16_t{1}, std::uint16_t{2}}) {
    Voltages v{24.0, 28.0, 12.0, 6.0, 16.8, 16.7, 48.4};
    Currents c{2.5, -1.2, 3.1, 0.8, -4.0, 1.5};
    Temperatures t{35, 22, kNoSensor, 61, 30};
    Status s;
    s.generator_rpm = 6100;
    s.generation_enabled = true;
    s.outputs = 0x0B;
    mix.push_back(*encode_voltages(v, addr));
    mix.push_back(*encode_currents(c, addr));
    mix.push_back(*encode_battery_energy({-1200, 340}, addr));
    mix.push_back(*encode_temperatures(t, addr));
    mix.push_back(*encode_status(s, addr));
    mix.push_back(*encode_get(PacketId::AvionicsVoltage, addr));
    mix.push_back(*encode_parameter_reply(Parameter::AvionicsVoltage, 240, addr));
    mix.push_back(*encode_enable_outputs(0x02, addr));
    mix.push_back(*encode_firmware({1, 17, 3, 4, 2025}, addr));
  }
  CanFrame foreign;
  foreign.id = 0x18FEF100;
  foreign.extended = true;
  foreign.length = 8;
  mix.push_back(foreign);

  char line[96];
  for (long i = 0; i < n; ++i) {
    const CanFrame& f = mix[static_cast<std::size_t>(i) % mix.size()];
    const long us = i * 131;  // ~7,634 frames/s: a saturated 1 Mbit/s bus
    int len = 0;
    if (screen) {
      len = std::snprintf(line, sizeof line, "  can0  %08" PRIX32 "   [%u] ", f.id, f.length);
      for (std::uint8_t b = 0; b < f.length; ++b)
        len += std::snprintf(line + len, sizeof line - static_cast<std::size_t>(len), " %02X", f.data[b]);
    } else {
      len = std::snprintf(line, sizeof line, "(%ld.%06ld) can0 %08" PRIX32 "#", 1700000000L + us / 1000000,
                          us % 1000000, f.id);
      for (std::uint8_t b = 0; b < f.length; ++b)
        len += std::snprintf(line + len, sizeof line - static_cast<std::size_t>(len), "%02X", f.data[b]);
    }
    line[len++] = '\n';
    std::fwrite(line, 1, static_cast<std::size_t>(len), stdout);
  }
  return 0;
}
