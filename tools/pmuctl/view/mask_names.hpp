#pragma once
// The bit masks of pmu::v5::Config by name, both ways: `config get` shows them as
// "avionics_servo,payload (0x03)", and `config set` takes names, a comma list, `none` or a
// number (interface.md section 3.2). The names are the codec's (messages.hpp).

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "pmu/codec/messages.hpp"

namespace pmu::tools {

struct MaskNames {
  std::string_view field;       // the Config field: "outputs", "packets_streamed", "power_up_state"
  const codec::NamedBit* bits;  // in bit order
  std::size_t count;
};

// The names of a Config mask field; nullptr for a field that is not a mask.
const MaskNames* mask_names(std::string_view field) noexcept;

// `config set PARAM VALUE`'s value, from the command line: the number to send, or why not
// (naming the bad token and what is valid). A mask parameter takes a comma list of its
// names, `none`, or a whole number (decimal or 0x hex); any other parameter a finite number in
// its unit. A stored parameter's value is then checked as the spec says (range, step, the
// bits the mask defines): only whether the unit's firmware has a power_up_state bit is left
// to the service, which knows the unit.
struct ConfigValue {
  std::optional<double> value;
  std::string error;  // set when value is empty
};
ConfigValue parse_config_value(std::string_view parameter, std::string_view text);

}  // namespace pmu::tools
