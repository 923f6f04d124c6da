#pragma once
// The named values of a decoded frame, in the order and with the names of interface.md, so
// the JSON and the table printers (and their tests) enumerate one list instead of each
// knowing every packet.

#include <cstdint>
#include <string_view>

#include "pmu/codec/canopen.hpp"
#include "pmu/codec/decode.hpp"

namespace pmu::tools {

struct FieldValue {
  enum class Kind : std::uint8_t { Number, Integer, Boolean } kind = Kind::Number;
  double number = 0;  // Number; NaN means "no value" (JSON null)
  std::int64_t integer = 0;
  bool boolean = false;

  static FieldValue of(double v) { return {Kind::Number, v, 0, false}; }
  static FieldValue of_int(std::int64_t v) { return {Kind::Integer, 0, v, false}; }
  static FieldValue of_bool(bool v) { return {Kind::Boolean, 0, 0, v}; }
};

// Receives one field: name, value, unit ("" when none).
class FieldSink {
 public:
  virtual void field(std::string_view name, const FieldValue& value, std::string_view unit) = 0;

 protected:
  ~FieldSink() = default;
};

// Every value a PMU frame carries; nothing for a zero-length request.
void visit_fields(const codec::PmuMessage& m, FieldSink& sink);
void visit_fields(const codec::canopen::CanOpenMessage& m, FieldSink& sink);

std::string_view bit6_meaning_name(codec::Bit6Meaning m);

}  // namespace pmu::tools
