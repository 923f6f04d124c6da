#include "pmu/transport/filters.hpp"

#include "pmu/codec/ids.hpp"

namespace pmu::transport {
namespace {

constexpr std::uint32_t kGroupMask = 0x1F000000u;  // bits 28..24 of a 29-bit id
constexpr std::uint32_t kExact11 = 0x7FFu;

}  // namespace

IdFilter pmu_filter() noexcept {
  return IdFilter{std::uint32_t{codec::kGroupId} << 24, kGroupMask, true};
}

std::vector<IdFilter> canopen_filters() {
  // spec/solar-boat-canopen-battery-mppt.txt: battery COB-IDs, then MPPT 0x4E6..0x51F
  // (eight devices at 0x4E6 + 8 * n, two ids each) covered by aligned power-of-two blocks.
  return {
      {0x202, kExact11, false}, {0x302, kExact11, false}, {0x402, kExact11, false},
      {0x482, kExact11, false},
      {0x4E6, 0x7FE, false},  // 0x4E6..0x4E7
      {0x4E8, 0x7F8, false},  // 0x4E8..0x4EF
      {0x4F0, 0x7F0, false},  // 0x4F0..0x4FF
      {0x500, 0x7E0, false},  // 0x500..0x51F
  };
}

std::vector<IdFilter> default_filters(bool with_canopen) {
  std::vector<IdFilter> filters{pmu_filter()};
  if (with_canopen) {
    const auto canopen = canopen_filters();
    filters.insert(filters.end(), canopen.begin(), canopen.end());
  }
  return filters;
}

bool accepts(const std::vector<IdFilter>& filters, const codec::CanFrame& frame) noexcept {
  if (filters.empty()) return true;
  for (const auto& filter : filters)
    if (filter.matches(frame)) return true;
  return false;
}

}  // namespace pmu::transport
