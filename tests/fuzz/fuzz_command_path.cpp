// libFuzzer target: serialized pmu::v5::Command bytes -> the whole command path of the service
// (read_command_cdr, parse_command, policy, rate limit, CommandService, the executor) against
// two simulated PMUs (firmware 1.17 and 1.12) on the in-process bus, with a fake clock.
// Checks the contract's invariants; a broken one traps, which libFuzzer reports as a crash
// with the input that caused it:
//   * every sample that reads as a pmu::v5::Command gets exactly one final reply, per request id
//     and sender (a resend is answered again, never executed twice);
//   * when no request ended COMPLETED, TIMEOUT or FAILED, no frame reached the bus
//     (REJECTED, DENIED and UNSUPPORTED send nothing);
//   * every frame on the bus decodes, and every value it sets is inside the spec's range.
//
// Input: records of [length: u16 little-endian][that many bytes of CDR payload], at most
// kMaxCommands; an input that is not such a sequence is one payload. Records alternate
// between two senders, so ids meet across senders.
#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "../support/harness.hpp"  // the fuzz targets do not link pmu::test_support
#include "pmu/codec/decode.hpp"
#include "pmu/codec/encode.hpp"
#include "pmu/dispatch/command_service.hpp"
#include "pmu/endpoints/command_cdr.hpp"

#include <spdlog/spdlog.h>

namespace pmu::service::test {
namespace {

constexpr std::size_t kMaxCommands = 8;

void require(bool ok) {
  if (!ok) __builtin_trap();
}

std::vector<std::vector<std::uint8_t>> split(const std::uint8_t* data, std::size_t size) {
  std::vector<std::vector<std::uint8_t>> out;
  std::size_t at = 0;
  while (at + 2 <= size && out.size() < kMaxCommands) {
    const std::size_t n = data[at] | (std::size_t{data[at + 1]} << 8);
    if (at + 2 + n > size) break;
    out.emplace_back(data + at + 2, data + at + 2 + n);
    at += 2 + n;
  }
  if (out.empty() || at != size) out.assign(1, std::vector<std::uint8_t>(data, data + size));
  return out;
}

bool acted(CommandResult r) {
  return r == CommandResult::Completed || r == CommandResult::Timeout || r == CommandResult::Failed;
}

// What the service may put on a bus: a known packet that decodes, with set values in range.
void check_frame(const codec::CanFrame& f) {
  const auto m = codec::decode(f);
  require(m.ok());
  require(m->address == 1 || m->address == 2 || m->address == codec::kBroadcastAddress ||
          m->packet == codec::PacketId::CanAddress);
  if (const auto* p = std::get_if<codec::ParameterValue>(&m->payload)) {
    if (!m->request) require(codec::to_raw(p->parameter, p->value).ok());
  }
}

int run_one(const std::uint8_t* data, std::size_t size) {
  spdlog::set_level(spdlog::level::off);
  Timeouts timeouts;
  Harness h(sim_bus({device(1), device(2)}), {pmu(1), pmu(2, codec::FirmwareVersion{1, 12})}, timeouts);
  h.run_for(300ms);  // identity and configuration read
  h.clear_sent();

  std::vector<CommandReplyData> replies;
  CommandService service({&h.worker()}, PolicyConfig{}, timeouts, h.clock(),
                         [&](const CommandReplyData& r) { replies.push_back(r); });

  std::map<std::string, std::size_t> submitted;  // by request id (both senders)
  std::size_t total = 0;
  const auto payloads = split(data, size);
  for (std::size_t i = 0; i < payloads.size(); ++i) {
    auto sample = read_command_cdr(payloads[i].data(), payloads[i].size());
    if (!sample) continue;
    sample->sender = i % 2 ? "ground-b" : "ground-a";
    ++submitted[sample->request_id];
    ++total;
    service.submit(*sample);
  }
  for (int step = 0; step < 3000 && replies.size() < total; ++step) h.run_for(10ms);
  h.run_for(500ms);  // anything late would show up now

  require(replies.size() == total);
  std::map<std::string, std::size_t> answered;
  bool any_acted = false;
  for (const auto& r : replies) {
    require(is_final(r.result));
    ++answered[r.request_id];
    any_acted = any_acted || acted(r.result);
  }
  require(answered == submitted);
  if (!any_acted) require(h.sent_frames().empty());
  for (const auto& f : h.sent_frames()) check_frame(f);
  return 0;
}

}  // namespace
}  // namespace pmu::service::test

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return pmu::service::test::run_one(data, size);
}
