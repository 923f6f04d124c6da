// The message table against the definitions: CRC_EXTRA, min and max payload length derived
// from the XML's fields with mavgen's rules (definitions.hpp), and the published values.

#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "definitions.hpp"
#include "pmu/mavlink/crc.hpp"
#include "pmu/mavlink/message_table.hpp"

namespace pmu::mavlink {
namespace {

using test::definitions;
using test::FieldDef;
using test::MessageDef;

unsigned type_size(const std::string& type) {
  if (type == "uint64_t" || type == "int64_t" || type == "double") return 8;
  if (type == "uint32_t" || type == "int32_t" || type == "float") return 4;
  if (type == "uint16_t" || type == "int16_t") return 2;
  return 1;  // uint8_t, int8_t, char
}

// Base fields sorted by element size, largest first (stable), then the extensions as declared.
std::vector<FieldDef> wire_order(const MessageDef& def) {
  std::vector<FieldDef> base;
  std::vector<FieldDef> ext;
  for (const auto& f : def.fields) (f.extension ? ext : base).push_back(f);
  std::stable_sort(base.begin(), base.end(),
                   [](const FieldDef& a, const FieldDef& b) { return type_size(a.type) > type_size(b.type); });
  base.insert(base.end(), ext.begin(), ext.end());
  return base;
}

std::uint16_t crc_text(const std::string& text, std::uint16_t crc) {
  return crc_accumulate(reinterpret_cast<const std::uint8_t*>(text.data()), text.size(), crc);
}

unsigned derived_crc_extra(const MessageDef& def) {
  std::uint16_t crc = crc_text(def.name + " ", kCrcInit);
  for (const auto& f : wire_order(def)) {
    if (f.extension) continue;
    crc = crc_text(f.type + " " + f.name + " ", crc);
    if (f.array_length != 0) crc = crc_accumulate(static_cast<std::uint8_t>(f.array_length), crc);
  }
  return static_cast<unsigned>((crc & 0xFFU) ^ (crc >> 8));
}

unsigned length_of(const MessageDef& def, bool with_extensions) {
  unsigned n = 0;
  for (const auto& f : def.fields) {
    if (f.extension && !with_extensions) continue;
    n += type_size(f.type) * std::max(1U, f.array_length);
  }
  return n;
}

TEST(MavlinkCrc, CheckValueOfCrc16Mcrf4xx) {
  const std::string check = "123456789";
  EXPECT_EQ(crc_text(check, kCrcInit), 0x6F91);
}

TEST(MavlinkTable, EveryDefinitionHasItsRow) {
  ASSERT_EQ(kMessageTable.size(), definitions().size());
  for (const auto& def : definitions()) {
    SCOPED_TRACE(def.name);
    const MessageInfo* info = find_message(def.id);
    ASSERT_NE(info, nullptr);
    EXPECT_EQ(info->name, def.name);
  }
}

TEST(MavlinkTable, CrcExtraDerivedFromTheFields) {
  for (const auto& def : definitions()) {
    SCOPED_TRACE(def.name);
    const MessageInfo* info = find_message(def.id);
    ASSERT_NE(info, nullptr);
    EXPECT_EQ(derived_crc_extra(def), def.published_crc_extra);
    EXPECT_EQ(info->crc_extra, def.published_crc_extra);
  }
}

TEST(MavlinkTable, PayloadLengthsDerivedFromTheFields) {
  for (const auto& def : definitions()) {
    SCOPED_TRACE(def.name);
    const MessageInfo* info = find_message(def.id);
    ASSERT_NE(info, nullptr);
    EXPECT_EQ(info->min_length, length_of(def, false));
    EXPECT_EQ(info->max_length, length_of(def, true));
  }
}

TEST(MavlinkTable, UnknownIdHasNoRow) {
  for (std::uint32_t id : {1U, 30U, 75U, 148U, 255U, 256U, 372U, 0xFFFFFFU}) {
    EXPECT_EQ(find_message(id), nullptr) << id;
  }
}

}  // namespace
}  // namespace pmu::mavlink
