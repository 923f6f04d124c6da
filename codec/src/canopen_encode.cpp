#include "pmu/codec/canopen_encode.hpp"

#include <cmath>
#include <cstddef>

#include "canopen_table.hpp"
#include "pmu/codec/canopen.hpp"

namespace pmu::codec::canopen {
namespace {

// Each enumerator's row in the shared table, checked by name at compile time so the enums
// cannot drift from the rows the decoder reads.
constexpr std::size_t kBatteryRow[kBatteryValueCount] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 13};
constexpr std::size_t kCellVoltageRow = 12;
constexpr std::size_t kTemperatureCollectionRow = 11;
constexpr std::size_t kChannelMapRow = 19;

static_assert(std::size(kBattery) == 14 && std::size(kMppt) == 20, "a table changed: revisit the enums");
static_assert(kBattery[kBatteryRow[static_cast<int>(BatteryValue::Voltage)]].name == "voltage");
static_assert(kBattery[kBatteryRow[static_cast<int>(BatteryValue::StateOfCharge)]].name == "state_of_charge");
static_assert(kBattery[kBatteryRow[static_cast<int>(BatteryValue::TimeToGo)]].name == "time_to_go");
static_assert(kBattery[kBatteryRow[static_cast<int>(BatteryValue::BmsState)]].name == "bms_state");
static_assert(kBattery[kBatteryRow[static_cast<int>(BatteryValue::PowerLevel)]].name == "power_level");
static_assert(kBattery[kCellVoltageRow].name == "cell_voltage");
static_assert(kBattery[kTemperatureCollectionRow].name == "temperature_collection");
static_assert(kMppt[static_cast<int>(MpptValue::Temperature)].name == "temperature");
static_assert(kMppt[static_cast<int>(MpptValue::CurrentPanel4Raw)].name == "current_panel_4_raw");
static_assert(kMppt[static_cast<int>(MpptValue::DutyCyclePanel1)].name == "duty_cycle_panel_1");
static_assert(kMppt[static_cast<int>(MpptValue::DutyCyclePanel4)].name == "duty_cycle_panel_4");
static_assert(kMppt[kChannelMapRow].name == "channel_active_map");

struct RawRange {
  long min, max;
};

constexpr RawRange range_of(Type t) noexcept {
  switch (t) {
    case Type::U8:
    case Type::U8x4: return {0, 255};
    case Type::I8: return {-128, 127};
    case Type::Bool: return {0, 1};
    case Type::U16: return {0, 65535};
    case Type::I16: return {-32768, 32767};
    case Type::U32: return {0, 4294967295L};
  }
  return {0, 0};
}

// CANopen expedited upload response: 0x43 | (4 - size) << 2 | expedited | size indicated.
constexpr std::uint8_t command_byte(std::uint8_t size) noexcept {
  return static_cast<std::uint8_t>(0x43 | ((4 - size) << 2));
}

EncodeError refuse(EncodeErrorKind kind, std::string_view field, std::string_view unit, double value, double min,
                   double max) noexcept {
  EncodeError e;
  e.kind = kind;
  e.field = field;
  e.unit = unit;
  e.value = value;
  e.min = min;
  e.max = max;
  return e;
}

// The value in the row's raw counts, rounded to its resolution, or why it does not fit.
Result<long, EncodeError> raw_of(const Entry& e, double value, std::string_view name) noexcept {
  const RawRange r = range_of(e.type);
  const double min = static_cast<double>(r.min) / e.divisor, max = static_cast<double>(r.max) / e.divisor;
  if (!std::isfinite(value)) return Unexpected{refuse(EncodeErrorKind::NotANumber, name, e.unit, value, min, max)};
  const double x = std::round(value * e.divisor);
  if (x < static_cast<double>(r.min) || x > static_cast<double>(r.max))
    return Unexpected{refuse(EncodeErrorKind::OutOfRange, name, e.unit, value, min, max)};
  return static_cast<long>(x);
}

void put_le(std::uint8_t* p, std::uint32_t v, std::uint8_t size) noexcept {
  for (std::uint8_t i = 0; i < size; ++i) p[i] = static_cast<std::uint8_t>((v >> (8 * i)) & 0xFFu);
}

// Header of a frame for row `e` on `cob_id`; `subindex` where the row's is a number (cell).
CanFrame header(const Entry& e, std::uint16_t cob_id, std::uint8_t subindex) noexcept {
  CanFrame f;
  f.id = cob_id;
  f.length = kMaxDataLength;
  f.data[0] = command_byte(size_of(e.type));
  const auto index = static_cast<std::uint16_t>(e.index == kAnyIndex ? 0 : e.index);
  put_le(f.data.data() + 1, index, 2);
  f.data[3] = static_cast<std::uint8_t>(e.subindex == kAnySubindex ? subindex : e.subindex);
  return f;
}

Result<std::uint16_t, EncodeError> battery_id(const Entry& e, std::uint8_t node) noexcept {
  if (node < 1 || node > kMaxNode)
    return Unexpected{refuse(EncodeErrorKind::OutOfRange, "node", "", node, 1, kMaxNode)};
  // The table's ids are node 2's; the function code is the rest.
  return static_cast<std::uint16_t>(e.cob_offset - kBatteryNode + node);
}

Result<std::uint16_t, EncodeError> mppt_id(const Entry& e, std::uint8_t device) noexcept {
  if (device >= kMpptDevices)
    return Unexpected{refuse(EncodeErrorKind::OutOfRange, "device", "", device, 0, kMpptDevices - 1)};
  return static_cast<std::uint16_t>(kMpptBase + kMpptStride * device + e.cob_offset);
}

Encoded scalar(const Entry& e, Result<std::uint16_t, EncodeError> id, double value,
               std::uint8_t subindex = 0) noexcept {
  if (!id) return Unexpected{id.error()};
  const auto raw = raw_of(e, value, e.name);
  if (!raw) return Unexpected{raw.error()};
  CanFrame f = header(e, *id, subindex);
  // Two's complement of a negative count is its wire form for the signed types.
  put_le(f.data.data() + kHeader, static_cast<std::uint32_t>(*raw), size_of(e.type));
  return f;
}

template <class T>
Encoded four(const Entry& e, Result<std::uint16_t, EncodeError> id, const std::array<T, 4>& values,
             const std::string_view (&names)[4]) noexcept {
  if (!id) return Unexpected{id.error()};
  CanFrame f = header(e, *id, 0);
  for (std::size_t i = 0; i < 4; ++i) {
    const auto raw = raw_of(e, static_cast<double>(values[i]), names[i]);
    if (!raw) return Unexpected{raw.error()};
    f.data[kHeader + i] = static_cast<std::uint8_t>(*raw);
  }
  return f;
}

// The names decode() gives each byte of a collection, for refusals.
constexpr std::string_view kTemperatureNames[4] = {"temperature_1", "temperature_2", "temperature_3", "temperature_4"};
constexpr std::string_view kChannelNames[4] = {"channel_1_active", "channel_2_active", "channel_3_active",
                                               "channel_4_active"};

}  // namespace

std::string_view name_of(BatteryValue v) noexcept {
  const auto i = static_cast<std::size_t>(v);
  return i < kBatteryValueCount ? kBattery[kBatteryRow[i]].name : std::string_view{};
}

std::string_view name_of(MpptValue v) noexcept {
  const auto i = static_cast<std::size_t>(v);
  return i < kMpptValueCount ? kMppt[i].name : std::string_view{};
}

Encoded encode_battery(BatteryValue v, double value, std::uint8_t node) noexcept {
  const auto i = static_cast<std::size_t>(v);
  if (i >= kBatteryValueCount)
    return Unexpected{refuse(EncodeErrorKind::OutOfRange, "battery value", "", double(i), 0, kBatteryValueCount - 1)};
  const Entry& e = kBattery[kBatteryRow[i]];
  return scalar(e, battery_id(e, node), value);
}

Encoded encode_cell_voltage(std::uint8_t cell, double volts, std::uint8_t node) noexcept {
  const Entry& e = kBattery[kCellVoltageRow];
  return scalar(e, battery_id(e, node), volts, cell);
}

Encoded encode_temperature_collection(const std::array<double, 4>& celsius, std::uint8_t node) noexcept {
  const Entry& e = kBattery[kTemperatureCollectionRow];
  return four(e, battery_id(e, node), celsius, kTemperatureNames);
}

Encoded encode_mppt(std::uint8_t device, MpptValue v, double value) noexcept {
  const auto i = static_cast<std::size_t>(v);
  if (i >= kMpptValueCount)
    return Unexpected{refuse(EncodeErrorKind::OutOfRange, "MPPT value", "", double(i), 0, kMpptValueCount - 1)};
  const Entry& e = kMppt[i];
  return scalar(e, mppt_id(e, device), value);
}

Encoded encode_channel_active_map(std::uint8_t device, const std::array<std::uint8_t, 4>& channels) noexcept {
  const Entry& e = kMppt[kChannelMapRow];
  return four(e, mppt_id(e, device), channels, kChannelNames);
}

}  // namespace pmu::codec::canopen
