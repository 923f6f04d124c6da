#include "pmu/transport/filters.hpp"

#include "pmu/codec/canopen.hpp"
#include "pmu/codec/ids.hpp"

namespace pmu::transport {
namespace {

constexpr std::uint32_t kGroupMask = 0x1F000000u;  // bits 28..24 of a 29-bit id
constexpr std::uint32_t kExact11 = 0x7FFu;

}  // namespace

IdFilter pmu_filter() noexcept { return IdFilter{std::uint32_t{codec::kGroupId} << 24, kGroupMask, true}; }

std::vector<IdFilter> canopen_filters() {
  // The codec's COB-IDs (canopen.hpp): each battery id exactly, then the MPPT range as the
  // aligned power-of-two blocks that cover it (0x4E6..0x51F: four filters, not sixteen).
  std::vector<IdFilter> filters;
  for (const auto id : codec::canopen::kBatteryCobIds) filters.push_back({id, kExact11, false});
  std::uint32_t lo = codec::canopen::kMpptBase;
  const std::uint32_t hi = codec::canopen::kMpptLastId;
  while (lo <= hi) {
    std::uint32_t size = 1;
    while (size < 0x800 && lo % (size * 2) == 0 && lo + size * 2 - 1 <= hi) size *= 2;
    filters.push_back({lo, kExact11 & ~(size - 1), false});
    lo += size;
  }
  return filters;
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
