#include <cstddef>

#include "pmu/sim/config.hpp"

namespace pmu::sim {
namespace {
std::size_t index(codec::Parameter p) noexcept { return static_cast<std::size_t>(p); }
}  // namespace

StoredParameters::StoredParameters() noexcept {
  using P = codec::Parameter;
  // Raw wire values; see the header for why these.
  set_raw(P::AvionicsVoltage, 120);
  set_raw(P::PayloadVoltage, 120);
  set_raw(P::ServoVoltage, 60);
  set_raw(P::BatteryVoltage, 252);
  set_raw(P::PacketPeriod, 10);
  set_raw(P::PacketsStreamed, codec::group_bit::All);
  set_raw(P::TemperatureOffset, 128);
  set_raw(P::UpperTemperatureLimit, 80);
  set_raw(P::PowerUpState, codec::output_bit::All);
  set_raw(P::CrankingTime, 50);
  set_raw(P::CanAddress, codec::kDefaultAddress);
}

std::uint32_t StoredParameters::raw(codec::Parameter p) const noexcept { return raw_[index(p)]; }

void StoredParameters::set_raw(codec::Parameter p, std::uint32_t raw) noexcept { raw_[index(p)] = raw; }

}  // namespace pmu::sim
