// Property tests: both decoders are total (every frame gives a value or an error, and the
// outcome depends only on the bytes the frame carries), and every device-side encoder's frame
// decodes back to what was encoded. Expected outcomes come from the spec's tables, restated
// below, never from the decoder. Inputs are exhaustive where cheap and otherwise drawn from a
// std::mt19937 with a fixed seed, so a failure reproduces.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstdint>
#include <optional>
#include <random>
#include <string_view>
#include <variant>
#include <vector>

#include "pmu/codec/canopen.hpp"
#include "pmu/codec/decode.hpp"
#include "pmu/codec/encode.hpp"

namespace pmu::codec {
namespace {

// ---- the spec, restated ------------------------------------------------------------------------

// Protocol v1.9 section 4.2, table 1: packet id and the number of data bytes of a frame carrying
// values; `zero_get` where a zero-length frame is valid: ids up to 0x20 ("if sent to the PMU with
// zero data bytes the PMU will return ... the current values"), 0x23 (5.21), 0x24..0x26 ("must
// be issued with zero data bytes"), 0x30 and 0x31 ("with zero data bytes"). 0x21 and 0x22 always
// carry their mask.
struct Table1Row {
  std::uint8_t packet;
  std::uint8_t length;
  bool zero_get;
};
constexpr Table1Row kTable1[] = {
    {0x00, 7, true},  {0x01, 6, true},  {0x02, 4, true}, {0x03, 5, true}, {0x04, 5, true}, {0x0F, 1, true},
    {0x10, 1, true},  {0x11, 1, true},  {0x12, 1, true}, {0x13, 1, true}, {0x14, 1, true}, {0x15, 1, true},
    {0x16, 1, true},  {0x17, 1, true},  {0x18, 1, true}, {0x19, 1, true}, {0x1B, 2, true}, {0x20, 1, true},
    {0x21, 1, false}, {0x22, 1, false}, {0x23, 1, true}, {0x24, 0, true}, {0x25, 0, true}, {0x26, 0, true},
    {0x30, 2, true},  {0x31, 6, true},
};

const Table1Row* table1(unsigned packet) {
  for (const auto& row : kTable1)
    if (row.packet == packet) return &row;
  return nullptr;
}

// The payload type a data frame of each packet decodes to (messages.hpp mirrors table 1).
bool payload_fits_packet(std::uint8_t packet, const Payload& p) {
  switch (packet) {
    case 0x00: return std::holds_alternative<Voltages>(p);
    case 0x01: return std::holds_alternative<Currents>(p);
    case 0x02: return std::holds_alternative<BatteryEnergy>(p);
    case 0x03: return std::holds_alternative<Temperatures>(p);
    case 0x04: return std::holds_alternative<Status>(p);
    case 0x0F: return std::holds_alternative<MeasurementRequest>(p);
    case 0x20: return std::holds_alternative<OutputStates>(p);
    case 0x21: return std::holds_alternative<EnableOutputs>(p);
    case 0x22: return std::holds_alternative<DisableOutputs>(p);
    case 0x23: return std::holds_alternative<GenerationState>(p);
    case 0x24:
    case 0x25:
    case 0x26: return std::holds_alternative<NoPayload>(p);
    case 0x30: return std::holds_alternative<SerialNumber>(p);
    case 0x31: return std::holds_alternative<FirmwareInfo>(p);
    default: return packet >= 0x10 && packet <= 0x1B && std::holds_alternative<ParameterValue>(p);
  }
}

// Section 4: group (bits 28..24) 0x1E, packet (23..16), address (15..0).
constexpr std::uint32_t pmu_id(unsigned packet, unsigned address) { return (0x1Eu << 24) | (packet << 16) | address; }

const std::optional<FirmwareVersion> kFirmwares[] = {
    std::nullopt,           FirmwareVersion{1, 11}, FirmwareVersion{1, 12}, FirmwareVersion{1, 13},
    FirmwareVersion{1, 14}, FirmwareVersion{1, 15}, FirmwareVersion{1, 16}, FirmwareVersion{1, 17}};

bool at_least(std::optional<FirmwareVersion> fw, int major, int minor) {
  return !fw || fw->major * 100 + fw->minor >= major * 100 + minor;  // unknown = current (1.17)
}

// ---- helpers -------------------------------------------------------------------------------------

std::uint32_t rand32(std::mt19937& rng) { return static_cast<std::uint32_t>(rng()); }
std::uint8_t random_byte(std::mt19937& rng) { return static_cast<std::uint8_t>(rand32(rng) & 0xFFu); }

CanFrame random_frame(std::uint32_t id, bool extended, bool remote, std::uint8_t length, std::mt19937& rng) {
  CanFrame f;
  f.id = id;
  f.extended = extended;
  f.remote = remote;
  f.length = length;
  for (auto& b : f.data) b = random_byte(rng);
  return f;
}

// The same frame with every byte past `length` replaced: a decoder that reads only the bytes
// the frame carries cannot tell the two apart.
CanFrame with_other_tail(CanFrame f) {
  for (std::size_t i = f.length; i < kMaxDataLength; ++i) f.data[i] = static_cast<std::uint8_t>(~f.data[i]);
  return f;
}

template <class T>
double num(T v) {
  return static_cast<double>(v);
}

bool same_number(double a, double b) { return (std::isnan(a) && std::isnan(b)) || a == b; }

// Everything a decoded PMU message says, flattened, so two outcomes can be compared.
struct Flatten {
  std::vector<double>& out;
  void add(std::initializer_list<double> values) const {
    for (double v : values) out.push_back(v);
  }
  void operator()(const NoPayload&) const { add({-1}); }
  void operator()(const Voltages& v) const {
    add({v.avionics, v.output_28v, v.payload, v.servo, v.battery_a, v.battery_b, v.generator});
  }
  void operator()(const Currents& c) const {
    add({c.avionics, c.output_28v, c.payload, c.servo, c.battery_a, c.battery_b});
  }
  void operator()(const BatteryEnergy& e) const { add({num(e.battery_a_mah), num(e.battery_b_mah)}); }
  void operator()(const Temperatures& t) const { add({t.internal, t.battery_a, t.battery_b, t.generator, t.starter}); }
  void operator()(const Status& s) const {
    add({num(s.generator_rpm), num(s.generation_enabled), num(s.thermal_shutdown), num(s.soa_shutdown),
         num(s.start_button), num(s.payload_shed), num(s.starter_ready), num(s.outputs),
         num(static_cast<std::uint8_t>(s.interpretation.bit6)), num(s.interpretation.firmware_known)});
  }
  void operator()(const MeasurementRequest& m) const { add({num(m.groups)}); }
  void operator()(const ParameterValue& p) const {
    add({num(static_cast<std::uint8_t>(p.parameter)), num(p.raw), p.value});
  }
  void operator()(const OutputStates& o) const { add({num(o.mask)}); }
  void operator()(const EnableOutputs& o) const { add({num(o.mask)}); }
  void operator()(const DisableOutputs& o) const { add({num(o.mask)}); }
  void operator()(const GenerationState& g) const { add({num(g.enabled)}); }
  void operator()(const SerialNumber& s) const { add({num(s.serial_number)}); }
  void operator()(const FirmwareInfo& f) const {
    add({num(f.firmware_major), num(f.firmware_minor), num(f.build_day), num(f.build_month), num(f.build_year)});
  }
};

std::vector<double> outcome(const Result<PmuMessage, DecodeError>& r) {
  std::vector<double> out;
  if (!r.ok()) {
    const DecodeError& e = r.error();
    out = {0, num(static_cast<std::uint8_t>(e.kind)), num(e.id), num(e.packet), num(e.length), num(e.expected)};
    return out;
  }
  out = {1,
         num(static_cast<std::uint8_t>(r->packet)),
         num(r->address),
         num(r->request),
         num(r->unsupported_by_firmware),
         static_cast<double>(r->payload.index())};
  std::visit(Flatten{out}, r->payload);
  return out;
}

std::vector<double> outcome(const Result<canopen::CanOpenMessage, canopen::Error>& r) {
  std::vector<double> out;
  if (!r.ok()) {
    const canopen::Error& e = r.error();
    out = {0, num(static_cast<std::uint8_t>(e.kind)), num(e.cob_id), num(e.index), num(e.subindex), num(e.needed)};
    return out;
  }
  out = {1,
         num(static_cast<std::uint8_t>(r->source)),
         num(r->cob_id),
         num(r->device),
         num(r->command_byte),
         num(r->index),
         num(r->subindex),
         num(r->field_count)};
  for (std::size_t i = 0; i < r->field_count; ++i) {
    out.push_back(r->fields[i].value);
    out.push_back(static_cast<double>(r->fields[i].name.size()));
    out.push_back(static_cast<double>(r->fields[i].unit.size()));
  }
  return out;
}

bool same_outcome(const std::vector<double>& a, const std::vector<double>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (!same_number(a[i], b[i])) return false;
  return true;
}

// ---- PMU decoder over all of group 0x1E ------------------------------------------------------------

// Every packet id 0..255 at addresses 0, 1 and broadcast, every length code 0..15, random data,
// with unknown firmware and each firmware the version histories name. The outcome is fixed by
// table 1 alone.
TEST(DecodeRobustness, EveryPacketIdEveryLengthInGroup1E) {
  std::mt19937 rng(0x1E0001);
  const std::uint16_t addresses[] = {0x0000, 0x0001, 0xFFFF};
  std::size_t values = 0, errors = 0;
  for (unsigned packet = 0; packet <= 0xFF; ++packet) {
    const Table1Row* row = table1(packet);
    for (std::uint16_t address : addresses) {
      for (std::uint8_t length = 0; length <= 15; ++length) {
        const std::uint32_t id = pmu_id(packet, address);
        const CanFrame f = random_frame(id, true, false, length, rng);
        const CanFrame f2 = with_other_tail(f);
        for (const auto& fw : kFirmwares) {
          SCOPED_TRACE(::testing::Message() << "id " << std::hex << id << " length " << std::dec << int{length}
                                            << " fw " << (fw ? fw->ordinal() : 0));
          const auto r = decode(f, fw);
          // Only the carried bytes matter.
          if (length <= kMaxDataLength) {
            ASSERT_TRUE(same_outcome(outcome(r), outcome(decode(f2, fw))));
          }
          // The frame and its data are never mixed up with canopen's frames.
          ASSERT_FALSE(canopen::decode(f).ok());
          ASSERT_EQ(canopen::decode(f).error().kind, canopen::ErrorKind::NotOurs);
          if (!row) {
            ASSERT_FALSE(r.ok());
            EXPECT_EQ(r.error().kind, DecodeErrorKind::UnknownPacket);
            EXPECT_EQ(r.error().packet, packet);
            EXPECT_EQ(r.error().id, id);
            ++errors;
            continue;
          }
          if (length > kMaxDataLength) {
            ASSERT_FALSE(r.ok()) << "length code " << int{length} << " decoded";
            EXPECT_EQ(r.error().kind, DecodeErrorKind::BadLength);
            EXPECT_EQ(r.error().length, length);
            ++errors;
            continue;
          }
          const bool zero_ok = length == 0 && row->zero_get;
          if (!zero_ok && length != row->length) {
            ASSERT_FALSE(r.ok());
            EXPECT_EQ(r.error().kind, DecodeErrorKind::WrongLength);
            EXPECT_EQ(r.error().expected, row->length);
            EXPECT_EQ(r.error().length, length);
            EXPECT_FALSE(r.error().describe().empty());
            ++errors;
            continue;
          }
          ASSERT_TRUE(r.ok()) << r.error().describe();
          ++values;
          EXPECT_EQ(static_cast<unsigned>(r->packet), packet);
          EXPECT_EQ(r->address, address);
          EXPECT_EQ(r->address, id & 0xFFFFu);
          EXPECT_EQ(r->request, length == 0);
          if (length == 0) {
            EXPECT_TRUE(std::holds_alternative<NoPayload>(r->payload));
          } else {
            EXPECT_TRUE(payload_fits_packet(row->packet, r->payload));
          }
          // v1.9 section 6.5: 0x0F exists from firmware 1.14.
          EXPECT_EQ(r->unsupported_by_firmware, packet == 0x0F && !at_least(fw, 1, 14));
        }
      }
    }
  }
  // Per address and firmware: 23 packets at their data length, 21 of them also at length 0
  // (all but 0x21, 0x22), and 0x24..0x26 at length 0 only.
  EXPECT_EQ(values, (23u + 21u + 3u) * 3u * 8u);
  EXPECT_EQ(values + errors, 256u * 3u * 16u * 8u);
}

TEST(DecodeRobustness, RemoteFramesInGroup1EAreErrors) {
  std::mt19937 rng(0x1E0002);
  for (const auto& row : kTable1) {
    for (std::uint8_t length = 0; length <= 15; ++length) {
      const auto r = decode(random_frame(pmu_id(row.packet, 1), true, true, length, rng));
      ASSERT_FALSE(r.ok());
      // v1.9 section 2: "only the data frame is used here".
      EXPECT_EQ(r.error().kind, DecodeErrorKind::RemoteFrame);
    }
  }
}

// Section 4.1: the PMU's group is 0x1E. Other groups, and identifiers with bits above 29 set,
// are not PMU frames (no masking may turn 0x3E000001 into 0x1E000001).
TEST(DecodeRobustness, OtherExtendedIdsAreNotOurs) {
  std::mt19937 rng(0x1E0003);
  for (int i = 0; i < 20000; ++i) {
    const std::uint32_t id = rand32(rng) & kMaxExtendedId;
    if ((id >> 24) == 0x1E) continue;
    const auto r = decode(random_frame(id, true, false, static_cast<std::uint8_t>(rand32(rng) % 16), rng));
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error().kind, DecodeErrorKind::NotOurs);
  }
  for (std::uint32_t id : {0x3E000001u, 0x5E000001u, 0xFE000001u, 0x9E31FFFFu, 0xFFFFFFFFu}) {
    const auto r = decode(random_frame(id, true, false, 7, rng));
    ASSERT_FALSE(r.ok()) << std::hex << id;
    EXPECT_EQ(r.error().kind, DecodeErrorKind::NotOurs);
  }
}

// ---- every 11-bit id ----------------------------------------------------------------------------------

// spec/solar-boat-canopen-battery-mppt.txt: battery 0x202, 0x302, 0x402, 0x482; MPPT
// 0x4E6 + 8 * device (0..7) and, for the third table, base + 1 (canopen.hpp).
bool spec_canopen_id(std::uint32_t id) {
  if (id == 0x202 || id == 0x302 || id == 0x402 || id == 0x482) return true;
  for (std::uint32_t d = 0; d < 8; ++d)
    if (id == 1254 + 8 * d || id == 1254 + 8 * d + 1) return true;
  return false;
}

TEST(CanOpenRobustness, IsCanOpenIdMatchesTheSpecIds) {
  unsigned count = 0;
  for (std::uint32_t id = 0; id <= kMaxStandardId; ++id) {
    EXPECT_EQ(canopen::is_canopen_id(id, false), spec_canopen_id(id)) << std::hex << id;
    EXPECT_FALSE(canopen::is_canopen_id(id, true)) << std::hex << id;
    count += spec_canopen_id(id) ? 1u : 0u;
  }
  EXPECT_EQ(count, 4u + 8u * 2u);
}

void check_canopen(const CanFrame& f, const Result<canopen::CanOpenMessage, canopen::Error>& r) {
  if (f.extended || !spec_canopen_id(f.id)) {
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error().kind, canopen::ErrorKind::NotOurs);
    return;
  }
  if (f.remote) {
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error().kind, canopen::ErrorKind::RemoteFrame);
    return;
  }
  if (!r.ok()) {
    const auto kind = r.error().kind;
    EXPECT_TRUE(kind == canopen::ErrorKind::TooShort || kind == canopen::ErrorKind::UnknownIndex ||
                kind == canopen::ErrorKind::UnknownSubindex);
    EXPECT_EQ(r.error().cob_id, f.id);
    EXPECT_FALSE(r.error().describe().empty());
    return;
  }
  // Header (4 bytes) plus at least one value byte.
  EXPECT_GE(f.length, 5);
  EXPECT_EQ(r->cob_id, f.id);
  EXPECT_GE(r->field_count, 1);
  EXPECT_LE(r->field_count, 4);
  EXPECT_EQ(r->command_byte, f.data[0]);
  const bool battery = f.id == 0x202 || f.id == 0x302 || f.id == 0x402 || f.id == 0x482;
  EXPECT_EQ(r->source, battery ? canopen::Source::Battery : canopen::Source::Mppt);
  EXPECT_EQ(r->device, battery ? 0u : (f.id - 1254u) / 8u);
  for (std::size_t i = 0; i < r->field_count; ++i) {
    EXPECT_FALSE(r->fields[i].name.empty());
    EXPECT_TRUE(std::isfinite(r->fields[i].value));
  }
}

// Every 11-bit id, every length code 0..15, data and remote frames, random data: the PMU
// decoder refuses them all (section 2: the PMU uses 29-bit ids); canopen::decode gives a value
// or an error that the spec's id list predicts.
TEST(CanOpenRobustness, EveryStandardIdEveryLength) {
  std::mt19937 rng(0x7FF);
  for (std::uint32_t id = 0; id <= kMaxStandardId; ++id) {
    for (std::uint8_t length = 0; length <= 15; ++length) {
      for (bool remote : {false, true}) {
        SCOPED_TRACE(::testing::Message()
                     << "id " << std::hex << id << std::dec << " length " << int{length} << (remote ? " remote" : ""));
        const CanFrame f = random_frame(id, false, remote, length, rng);
        const auto pmu = decode(f);
        ASSERT_FALSE(pmu.ok());
        EXPECT_EQ(pmu.error().kind, DecodeErrorKind::NotOurs);
        const auto r = canopen::decode(f);
        check_canopen(f, r);
        if (length <= kMaxDataLength) {
          ASSERT_TRUE(same_outcome(outcome(r), outcome(canopen::decode(with_other_tail(f)))));
        } else if (!remote && spec_canopen_id(id)) {
          // canopen.cpp reads a length code above 8 as 8 bytes (classic CAN, ISO 11898-1:
          // DLC 9..15 means 8 data bytes), so it never reads past the 8 bytes of data.
          CanFrame eight = f;
          eight.length = kMaxDataLength;
          const auto r8 = canopen::decode(eight);
          ASSERT_EQ(r.ok(), r8.ok());
          if (r.ok()) {
            ASSERT_TRUE(same_outcome(outcome(r), outcome(r8)));
          }
        }
      }
    }
  }
}

// The table ids again, with headers that hit the tables: every subindex under the documented
// index, another index and a random one, every length 0..8.
TEST(CanOpenRobustness, EverySubindexOfEveryTableId) {
  std::mt19937 rng(0x2005);
  std::size_t values = 0;
  for (std::uint32_t id = 0; id <= kMaxStandardId; ++id) {
    if (!spec_canopen_id(id)) continue;
    for (unsigned sub = 0; sub <= 0xFF; ++sub) {
      for (std::uint16_t index :
           {std::uint16_t{0x2005}, std::uint16_t{0x2000}, static_cast<std::uint16_t>(rand32(rng) & 0xFFFFu)}) {
        for (std::uint8_t length = 0; length <= kMaxDataLength; ++length) {
          CanFrame f = random_frame(id, false, false, length, rng);
          f.data[1] = static_cast<std::uint8_t>(index & 0xFFu);
          f.data[2] = static_cast<std::uint8_t>(index >> 8);
          f.data[3] = static_cast<std::uint8_t>(sub);
          const auto r = canopen::decode(f);
          check_canopen(f, r);
          if (r.ok()) {
            ++values;
            EXPECT_EQ(r->subindex, sub);
          }
        }
      }
    }
  }
  EXPECT_GT(values, 0u);
}

// Arbitrary frames: ids of any 32 bits, either flag, any length code, either firmware.
TEST(Robustness, RandomFramesAreTotal) {
  std::mt19937 rng(20240601);
  std::size_t pmu_values = 0, canopen_values = 0;
  for (int i = 0; i < 200000; ++i) {
    const std::uint32_t bits = rand32(rng);
    const bool extended = (bits & 1u) != 0, remote = (bits & 2u) == 0 && (bits & 4u) != 0;
    const auto length = static_cast<std::uint8_t>((bits >> 3) & 0x0Fu);
    std::uint32_t id = rand32(rng);
    if ((bits & 0x80u) != 0) id = (id & 0x00FFFFFFu) | (0x1Eu << 24);  // often in the PMU group
    if (!extended) id &= (bits & 0x100u) != 0 ? 0x7FFu : 0xFFFFFFFFu;
    const CanFrame f = random_frame(id, extended, remote, length, rng);
    const std::optional<FirmwareVersion> fw = (bits & 0x200u) != 0
                                                  ? std::optional<FirmwareVersion>{}
                                                  : FirmwareVersion{1, static_cast<std::uint8_t>(bits >> 24)};
    const auto r = decode(f, fw);
    if (r.ok()) {
      ++pmu_values;
      EXPECT_TRUE(f.extended && !f.remote && f.length <= kMaxDataLength);
      EXPECT_EQ(f.id >> 24, 0x1Eu);
      EXPECT_EQ(r->address, f.id & 0xFFFFu);
      EXPECT_EQ(static_cast<std::uint32_t>(r->packet), (f.id >> 16) & 0xFFu);
    } else {
      EXPECT_EQ(r.error().id, f.id);
      EXPECT_FALSE(r.error().describe().empty());
    }
    const auto c = canopen::decode(f);
    canopen_values += c.ok() ? 1u : 0u;
    if (!f.extended && f.id <= kMaxStandardId) {
      check_canopen(f, c);
    } else {
      ASSERT_FALSE(c.ok());
      EXPECT_EQ(c.error().kind, canopen::ErrorKind::NotOurs);
    }
  }
  // The sample reaches the success paths of both decoders, not only their first checks.
  EXPECT_GT(pmu_values, 100u);
  EXPECT_GT(canopen_values, 0u);
}

// ---- encode -> decode round trips, device side ---------------------------------------------------------

const std::uint16_t kAddresses[] = {0x0000, 0x0001, 0x1234, 0xFFFE, 0xFFFF};

// The frame an encoder made: right id (section 4) and table 1 length.
void expect_frame(const Encoded& e, std::uint8_t packet, std::uint16_t address) {
  ASSERT_TRUE(e.ok()) << e.error().describe();
  EXPECT_TRUE(e->extended);
  EXPECT_FALSE(e->remote);
  EXPECT_EQ(e->id, pmu_id(packet, address));
  EXPECT_EQ(e->length, table1(packet)->length);
}

template <class T>
T decoded(const Encoded& e, std::optional<FirmwareVersion> fw = std::nullopt) {
  const auto r = decode(e.value(), fw);
  EXPECT_TRUE(r.ok()) << r.error().describe();
  if (!r.ok()) return T{};
  EXPECT_FALSE(r->request);
  EXPECT_TRUE(std::holds_alternative<T>(r->payload));
  if (!std::holds_alternative<T>(r->payload)) return T{};
  return std::get<T>(r->payload);
}

// Table 2: raw bytes 0..250 (servo 0..125); avionics, payload, servo, batteries x10, 28 V x5,
// generator x2.5.
TEST(RoundTrip, Voltages) {
  for (std::uint16_t address : kAddresses) {
    for (int raw = 0; raw <= 250; ++raw) {
      SCOPED_TRACE(raw);
      const int servo = raw > 125 ? 125 : raw;
      const Voltages v{raw / 10.0, raw / 5.0, raw / 10.0, servo / 10.0, raw / 10.0, raw / 10.0, raw / 2.5};
      const Encoded e = encode_voltages(v, address);
      expect_frame(e, 0x00, address);
      const int expected_bytes[] = {raw, raw, raw, servo, raw, raw, raw};
      for (std::size_t i = 0; i < 7; ++i) EXPECT_EQ(e->data[i], expected_bytes[i]) << i;
      const auto d = decoded<Voltages>(e);
      EXPECT_DOUBLE_EQ(d.avionics, v.avionics);
      EXPECT_DOUBLE_EQ(d.output_28v, v.output_28v);
      EXPECT_DOUBLE_EQ(d.payload, v.payload);
      EXPECT_DOUBLE_EQ(d.servo, v.servo);
      EXPECT_DOUBLE_EQ(d.battery_a, v.battery_a);
      EXPECT_DOUBLE_EQ(d.battery_b, v.battery_b);
      EXPECT_DOUBLE_EQ(d.generator, v.generator);
    }
  }
}

// Table 3: avionics, payload, servo unsigned 0..100; 28 V and batteries signed -125..125; x10.
TEST(RoundTrip, Currents) {
  for (std::uint16_t address : kAddresses) {
    for (int raw = -125; raw <= 125; ++raw) {
      SCOPED_TRACE(raw);
      const int u2 = std::min(std::abs(raw), 100);  // the unsigned fields, 0..100
      const Currents c{u2 / 10.0, raw / 10.0, u2 / 10.0, u2 / 10.0, raw / 10.0, -raw / 10.0};
      const Encoded e = encode_currents(c, address);
      expect_frame(e, 0x01, address);
      EXPECT_EQ(e->data[0], u2);
      EXPECT_EQ(e->data[1], static_cast<std::uint8_t>(raw & 0xFF));  // two's complement
      EXPECT_EQ(e->data[5], static_cast<std::uint8_t>(-raw & 0xFF));
      const auto d = decoded<Currents>(e);
      EXPECT_DOUBLE_EQ(d.avionics, c.avionics);
      EXPECT_DOUBLE_EQ(d.output_28v, c.output_28v);
      EXPECT_DOUBLE_EQ(d.payload, c.payload);
      EXPECT_DOUBLE_EQ(d.servo, c.servo);
      EXPECT_DOUBLE_EQ(d.battery_a, c.battery_a);
      EXPECT_DOUBLE_EQ(d.battery_b, c.battery_b);
    }
  }
}

// Table 4: two signed 16-bit mAh values, big-endian (section 5), every value.
TEST(RoundTrip, BatteryEnergy) {
  for (std::uint16_t address : {std::uint16_t{1}, std::uint16_t{0xFFFF}}) {
    for (int mah = -32768; mah <= 32767; ++mah) {
      const BatteryEnergy b{static_cast<std::int16_t>(mah), static_cast<std::int16_t>(-1 - mah)};
      const Encoded e = encode_battery_energy(b, address);
      ASSERT_TRUE(e.ok());
      const auto word = static_cast<std::uint16_t>(mah & 0xFFFF);
      ASSERT_EQ(e->data[0], word >> 8);
      ASSERT_EQ(e->data[1], word & 0xFF);
      const auto d = decoded<BatteryEnergy>(e);
      ASSERT_EQ(d.battery_a_mah, mah);
      ASSERT_EQ(d.battery_b_mah, -1 - mah);
    }
    expect_frame(encode_battery_energy({-32768, 32767}, address), 0x02, address);
  }
}

// Table 5: internal and external sensors -127..127 or "no sensor" (-128, NaN here), starter
// -49..127 or "no sensor". External sensing exists from firmware 1.12 (v1.9 section 6.1).
TEST(RoundTrip, Temperatures) {
  for (std::uint16_t address : kAddresses) {
    for (int t = -128; t <= 127; ++t) {
      SCOPED_TRACE(t);
      const double external = t == -128 ? kNoSensor : t;
      const double starter = t == -128 ? kNoSensor : t < -49 ? -49.0 : t;
      const Temperatures in{external, external, external, external, starter};
      const Encoded e = encode_temperatures(in, address);
      expect_frame(e, 0x03, address);
      EXPECT_EQ(e->data[0], static_cast<std::uint8_t>(t & 0xFF));
      EXPECT_EQ(e->data[1], static_cast<std::uint8_t>(t & 0xFF));  // NaN is sent as -128 (0x80)
      for (const auto& fw : kFirmwares) {
        const auto d = decoded<Temperatures>(e, fw);
        EXPECT_TRUE(same_number(d.internal, in.internal));
        EXPECT_TRUE(same_number(d.starter, in.starter));
        if (at_least(fw, 1, 12)) {
          EXPECT_TRUE(same_number(d.battery_a, external));
          EXPECT_TRUE(same_number(d.battery_b, external));
          EXPECT_TRUE(same_number(d.generator, external));
        } else {
          EXPECT_TRUE(std::isnan(d.battery_a) && std::isnan(d.battery_b) && std::isnan(d.generator));
        }
      }
    }
  }
}

// Table 6: rpm big-endian 0..65535; flag register 0 bits 4..7, register 1 bit 7, register 2
// bits 0..3. Bit 6 of register 0 is the start button before 1.16 and the SOA shutdown flag
// from 1.16 (section 6.8); the starter-ready flag exists from 1.12 (section 6.1).
TEST(RoundTrip, Status) {
  for (const auto& fw : kFirmwares) {
    const bool soa = at_least(fw, 1, 16), starter = at_least(fw, 1, 12);
    for (unsigned flags = 0; flags < 64; ++flags) {
      for (std::uint8_t outputs = 0; outputs <= 0x0F; ++outputs) {
        Status s;
        s.generator_rpm = static_cast<std::uint16_t>(flags * 1000u + outputs);
        s.generation_enabled = flags & 1u;
        s.thermal_shutdown = flags & 2u;
        s.soa_shutdown = flags & 4u;
        s.start_button = flags & 8u;
        s.payload_shed = flags & 16u;
        s.starter_ready = flags & 32u;
        s.outputs = outputs;
        const Encoded e = encode_status(s, 0x0001, fw);
        expect_frame(e, 0x04, 0x0001);
        const bool bit6 = soa ? s.soa_shutdown : s.start_button;
        const int reg0 = (s.generation_enabled ? 0x10 : 0) | (s.thermal_shutdown ? 0x20 : 0) | (bit6 ? 0x40 : 0) |
                         (s.payload_shed ? 0x80 : 0);
        EXPECT_EQ(e->data[2], reg0);
        EXPECT_EQ(e->data[3], starter && s.starter_ready ? 0x80 : 0x00);
        EXPECT_EQ(e->data[4], outputs);
        const auto d = decoded<Status>(e, fw);
        EXPECT_EQ(d.generator_rpm, s.generator_rpm);
        EXPECT_EQ(d.generation_enabled, s.generation_enabled);
        EXPECT_EQ(d.thermal_shutdown, s.thermal_shutdown);
        EXPECT_EQ(d.soa_shutdown, soa && s.soa_shutdown);
        EXPECT_EQ(d.start_button, !soa && s.start_button);
        EXPECT_EQ(d.payload_shed, s.payload_shed);
        EXPECT_EQ(d.starter_ready, starter && s.starter_ready);
        EXPECT_EQ(d.outputs, outputs);
        EXPECT_EQ(d.interpretation.firmware_known, fw.has_value());
      }
    }
  }
  for (unsigned rpm = 0; rpm <= 0xFFFF; rpm += 257) {
    Status s;
    s.generator_rpm = static_cast<std::uint16_t>(rpm);
    const Encoded e = encode_status(s, 7);
    ASSERT_TRUE(e.ok());
    EXPECT_EQ(e->data[0], rpm >> 8);
    EXPECT_EQ(e->data[1], rpm & 0xFF);
    EXPECT_EQ(decoded<Status>(e).generator_rpm, rpm);
  }
  Status bad;
  bad.outputs = 0x10;  // bits 4..7 of flag register 2 are not defined
  EXPECT_FALSE(encode_status(bad, 1).ok());
}

// Tables 8..18: the raw byte (two, big-endian, for CA) and its engineering value. A reply
// carries whatever the device holds, so every raw value that fits the field round-trips.
struct ParamRow {
  Parameter parameter;
  std::uint8_t packet;
  double divisor;  // engineering value = raw / divisor
  unsigned max_raw;
};
const ParamRow kParams[] = {
    {Parameter::AvionicsVoltage, 0x10, 10, 0xFF},  {Parameter::PayloadVoltage, 0x11, 10, 0xFF},
    {Parameter::ServoVoltage, 0x12, 10, 0xFF},     {Parameter::BatteryVoltage, 0x13, 10, 0xFF},
    {Parameter::PacketPeriod, 0x14, 10, 0xFF},     {Parameter::PacketsStreamed, 0x15, 1, 0xFF},
    {Parameter::TemperatureOffset, 0x16, 1, 0xFF}, {Parameter::UpperTemperatureLimit, 0x17, 1, 0xFF},
    {Parameter::PowerUpState, 0x18, 1, 0xFF},      {Parameter::CrankingTime, 0x19, 10, 0xFF},
    {Parameter::CanAddress, 0x1B, 1, 0xFFFF},
};

TEST(RoundTrip, ParameterReplies) {
  for (const auto& p : kParams) {
    SCOPED_TRACE(static_cast<int>(p.packet));
    for (std::uint16_t address : {std::uint16_t{0}, std::uint16_t{0xFFFF}}) {
      expect_frame(encode_parameter_reply(p.parameter, 0, address), p.packet, address);
    }
    for (unsigned raw = 0; raw <= p.max_raw; ++raw) {
      const Encoded e = encode_parameter_reply(p.parameter, raw, 1);
      ASSERT_TRUE(e.ok()) << raw;
      if (p.max_raw == 0xFFFF) {
        ASSERT_EQ(e->data[0], raw >> 8);
        ASSERT_EQ(e->data[1], raw & 0xFF);
      } else {
        ASSERT_EQ(e->data[0], raw);
      }
      const auto d = decoded<ParameterValue>(e);
      ASSERT_EQ(d.parameter, p.parameter);
      ASSERT_EQ(d.raw, raw);
      ASSERT_DOUBLE_EQ(d.value, raw / p.divisor);
    }
    // One past the field's width cannot be put on the wire.
    EXPECT_FALSE(encode_parameter_reply(p.parameter, p.max_raw + 1, 1).ok());
  }
}

// Table 19: bits 0..3 are outputs; table 22: bit 0 is generation; tables 23, 24.
TEST(RoundTrip, OutputsGenerationSerialFirmware) {
  for (std::uint16_t address : kAddresses) {
    for (unsigned mask = 0; mask <= 0xFF; ++mask) {
      const Encoded e = encode_outputs_reply(static_cast<std::uint8_t>(mask), address);
      if (mask > 0x0F) {
        EXPECT_FALSE(e.ok()) << mask;
        continue;
      }
      expect_frame(e, 0x20, address);
      EXPECT_EQ(e->data[0], mask);
      EXPECT_EQ(decoded<OutputStates>(e).mask, mask);
    }
    for (bool on : {false, true}) {
      const Encoded e = encode_generation_reply(on, address);
      expect_frame(e, 0x23, address);
      EXPECT_EQ(e->data[0], on ? 1 : 0);
      EXPECT_EQ(decoded<GenerationState>(e).enabled, on);
    }
  }
  for (unsigned serial = 0; serial <= 0xFFFF; ++serial) {
    const Encoded e = encode_serial(static_cast<std::uint16_t>(serial), 1);
    ASSERT_TRUE(e.ok());
    ASSERT_EQ(e->data[0], serial >> 8);
    ASSERT_EQ(e->data[1], serial & 0xFF);
    ASSERT_EQ(decoded<SerialNumber>(e).serial_number, serial);
  }
  expect_frame(encode_serial(0, 0xFFFF), 0x30, 0xFFFF);
  for (std::uint8_t major = 0; major <= 99; ++major) {
    for (std::uint8_t minor = 0; minor <= 99; ++minor) {
      const FirmwareInfo in{major, minor, static_cast<std::uint8_t>(1 + (major + minor) % 31),
                            static_cast<std::uint8_t>(1 + minor % 12),
                            static_cast<std::uint16_t>(2015 + major * 100 + minor)};
      const Encoded e = encode_firmware(in, 1);
      ASSERT_TRUE(e.ok());
      ASSERT_EQ(e->data[0], major);
      ASSERT_EQ(e->data[1], minor);
      ASSERT_EQ(e->data[4], in.build_year >> 8);
      ASSERT_EQ(e->data[5], in.build_year & 0xFF);
      const auto d = decoded<FirmwareInfo>(e);
      ASSERT_EQ(d.firmware_major, major);
      ASSERT_EQ(d.firmware_minor, minor);
      ASSERT_EQ(d.build_day, in.build_day);
      ASSERT_EQ(d.build_month, in.build_month);
      ASSERT_EQ(d.build_year, in.build_year);
    }
  }
  expect_frame(encode_firmware({1, 17, 31, 12, 2023}, 0xFFFE), 0x31, 0xFFFE);
}

}  // namespace
}  // namespace pmu::codec
