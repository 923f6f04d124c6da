#pragma once
// `pmuctl decode --mcap OUT.mcap LOG`: a candump log into an MCAP file with the channels of
// `pmuctl record` (docs/interface.md, "MCAP recordings"): each PMU telemetry frame becomes
// the sample pmu-service would have published for it (vehicle "", bus = the log's
// interface, the PMU's address), serialized by the generated code, log time = the
// candump timestamp. A regular OUT appears only when complete (written beside it, then
// renamed): a failure leaves OUT as it was and no half-written file. A FIFO, a character
// device and "-" (standard output) are written in place (mcap_recording.hpp).

#include <optional>
#include <string>

#include "pmu/codec/firmware.hpp"

namespace pmu::tools {

// Exit status: 0 done, 1 the output could not be written (disk full), 2 bad input (cannot
// read LOG; OUT cannot be created or is refused: a directory, ...). What went wrong on stderr.
int run_decode_mcap(const std::string& log, const std::string& out, std::optional<codec::FirmwareVersion> firmware);

}  // namespace pmu::tools
