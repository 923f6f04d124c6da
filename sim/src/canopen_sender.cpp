#include "canopen_sender.hpp"

#include <utility>

namespace pmu::sim::detail {
namespace {

constexpr std::uint8_t kHeader = 4;  // command byte, index (2), subindex

// The value's size from Data[0], the expedited upload response the codec writes.
std::uint8_t value_size(const codec::CanFrame& f) noexcept {
  return static_cast<std::uint8_t>(4 - ((f.data[0] >> 2) & 0x3));
}

void shorten(codec::CanFrame& f) noexcept { f.length = static_cast<std::uint8_t>(kHeader + value_size(f) - 1); }

}  // namespace

Spread::Spread(Duration period, std::size_t count, TimePoint start) noexcept
    : period_(period), count_(count == 0 ? 1 : count), start_(start) {}

TimePoint Spread::next() const noexcept {
  return start_ + period_ * static_cast<Duration::rep>(slot_) / static_cast<Duration::rep>(count_);
}

CanOpenSender::CanOpenSender(FrameSink sink) noexcept : sink_(std::move(sink)) {}

void CanOpenSender::send(const codec::Encoded& frame, const Spoil& spoil) noexcept {
  if (!frame) {
    ++counters_.encode_errors;
    return;
  }
  if (faults_.silent) {
    ++counters_.suppressed;
    return;
  }
  codec::CanFrame f = *frame;
  switch (faults_.garble) {
    case Garble::None: break;
    case Garble::WrongLength:
      shorten(f);
      ++counters_.garbled;
      break;
    case Garble::UnknownSubindex:
      if (spoil.blank_subindex) {
        f.data[3] = *spoil.blank_subindex;
      } else if (spoil.unknown_index) {
        f.data[1] = static_cast<std::uint8_t>(*spoil.unknown_index & 0xFF);
        f.data[2] = static_cast<std::uint8_t>(*spoil.unknown_index >> 8);
      } else {
        shorten(f);
      }
      ++counters_.garbled;
      break;
  }
  ++counters_.frames_out;
  if (sink_) sink_(f);
}

}  // namespace pmu::sim::detail
