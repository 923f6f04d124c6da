#include "pmu/dds/command_sample.hpp"

#include <unistd.h>

#include <type_traits>

#include "pmu/codec/ids.hpp"
#include "pmu/codec/parameters.hpp"

namespace pmu::dds {

static_assert(static_cast<int>(pmu::v5::GET_FIRMWARE) == static_cast<int>(service::CommandKind::GetFirmware),
              "the contract's kinds and the service's are in one order");
static_assert(static_cast<int>(pmu::v5::IN_PROGRESS) == static_cast<int>(service::CommandResult::InProgress),
              "the contract's results and the service's are in one order");

// The names are literals, so data() ends in NUL.
const char* result_name(pmu::v5::CommandResult r) { return service::to_string(command_result(r)).data(); }

service::CommandResult command_result(pmu::v5::CommandResult r) noexcept {
  const auto n = static_cast<unsigned>(r);
  if (n > static_cast<unsigned>(service::CommandResult::InProgress)) return service::CommandResult::Failed;
  return static_cast<service::CommandResult>(n);
}

std::string request_id_prefix(std::string_view program, std::size_t host_bytes) {
  char host[64] = "host";
  ::gethostname(host, sizeof host - 1);
  return std::string(program) + "-" + std::string(host).substr(0, host_bytes) + "-" + std::to_string(::getpid()) + "-";
}

std::string request_id(std::string_view program) {
  const auto ns =
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch()).count();
  return request_id_prefix(program) + std::to_string(ns);
}

std::uint64_t epoch_ns_at(std::chrono::steady_clock::time_point deadline) {
  const auto left =
      std::chrono::duration_cast<std::chrono::system_clock::duration>(deadline - std::chrono::steady_clock::now());
  const auto t = std::chrono::system_clock::now() + left;
  return static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(t.time_since_epoch()).count());
}

void put_action(const service::CommandAction& action, pmu::v5::Command& c) {
  c.kind(static_cast<pmu::v5::CommandKind>(action.index()));
  std::visit(
      [&](const auto& a) {
        using A = std::decay_t<decltype(a)>;
        namespace act = service::action;
        if constexpr (std::is_same_v<A, act::Get>) {
          c.parameter(std::string(codec::packet_name(a.packet)));
        } else if constexpr (std::is_same_v<A, act::SetParameter>) {
          c.parameter(std::string(codec::spec_of(a.parameter).name));
          c.value(codec::parameter_value(a.parameter, a.raw));
        } else if constexpr (std::is_same_v<A, act::SetOutputs> || std::is_same_v<A, act::EnableOutputs> ||
                             std::is_same_v<A, act::DisableOutputs>) {
          c.outputs(a.mask);
        } else if constexpr (std::is_same_v<A, act::SetGeneration>) {
          c.enable(a.enable);
        } else if constexpr (std::is_same_v<A, act::RequestMeasurements>) {
          c.groups(a.groups);
        }
      },
      action);
}

}  // namespace pmu::dds
