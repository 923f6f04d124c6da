#pragma once
// The "no value" values of the service's own types, which the contract publishes as NaN from
// contract v5 on (docs/interface.md sections 1.1, 10.5): a viewer that plots the samples
// (Foxglove, PlotJuggler) cannot know a sentinel, and would draw 65535 rpm or -1 s as
// measurements. The service's types keep them (its rules compare against them); the DDS
// edge turns them into NaN, and the previous contract's participant turns NaN back into
// them (previous_contract.hpp), so its consumers read what they always read.

#include <cmath>
#include <cstdint>
#include <limits>

namespace pmu::service {

inline constexpr float kNoValue = std::numeric_limits<float>::quiet_NaN();
// codec::Status::generator_rpm when the PMU has no reading: the top of its 16-bit field.
inline constexpr std::uint16_t kNoRpm = std::numeric_limits<std::uint16_t>::max();
// A battery's time_to_go (s) while it is not discharging: the top of the document's 16-bit
// minutes (canopen_values.hpp scales them to seconds), which the document defines no meaning for.
inline constexpr double kNotDischarging = double{std::numeric_limits<std::uint16_t>::max()} * 60;
// HealthReport::last_frame_age of a device never heard.
inline constexpr double kNeverHeard = -1;

inline float rpm_or_nan(std::uint16_t rpm) { return rpm == kNoRpm ? kNoValue : static_cast<float>(rpm); }
inline float time_to_go_or_nan(double s) { return s == kNotDischarging ? kNoValue : static_cast<float>(s); }
inline float frame_age_or_nan(double s) { return s < 0 ? kNoValue : static_cast<float>(s); }

}  // namespace pmu::service
