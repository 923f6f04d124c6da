#include "pmu/session/reading_machine.hpp"

namespace pmu::service {

const std::vector<codec::PacketId>& ReadingMachine::packets() {
  static const std::vector<codec::PacketId> v = [] {
    std::vector<codec::PacketId> p{codec::PacketId::Serial, codec::PacketId::Firmware};
    for (const auto& s : codec::parameter_table()) p.push_back(s.packet);
    p.push_back(codec::PacketId::Outputs);
    p.push_back(codec::PacketId::Generation);
    return p;
  }();
  return v;
}

std::uint64_t ReadingMachine::start() noexcept {
  phase_ = Phase::Reading;
  failed_ = false;
  left_ = static_cast<unsigned>(packets().size());
  return ++round_;
}

ReadingMachine::Progress ReadingMachine::on_result(std::uint64_t round, bool answered,
                                                   std::chrono::steady_clock::time_point now,
                                                   std::chrono::milliseconds retry_delay) noexcept {
  if (round != round_ || phase_ != Phase::Reading || failed_) return Progress::Ignored;
  if (!answered) {
    // One silent get means a silent device: the rest of the round would time out in turn.
    failed_ = true;
    retry_at_ = now + retry_delay;
    return Progress::Failed;
  }
  if (--left_ > 0) return Progress::Pending;
  phase_ = Phase::Running;
  return Progress::Done;
}

std::optional<codec::FirmwareVersion> ReadingMachine::firmware() const noexcept {
  if (!info_ || !info_->firmware_known) return std::nullopt;
  return info_->firmware.version();
}

std::uint32_t ReadingMachine::all_heard() noexcept {
  return static_cast<std::uint32_t>((std::uint64_t{1} << packets().size()) - 1);
}

ReadingMachine::Changes ReadingMachine::absorb(const codec::PmuMessage& m) {
  Changes c;
  const auto& round = packets();
  for (std::size_t i = 0; i < round.size(); ++i)
    if (round[i] == m.packet) heard_ |= std::uint32_t{1} << i;
  auto set = [&c](auto& slot, auto value) {
    if (slot != value) {
      slot = value;
      c.config = true;
    }
  };
  if (const auto* p = std::get_if<codec::ParameterValue>(&m.payload)) {
    set(config_.raw[static_cast<std::size_t>(p->parameter)], std::optional<std::uint32_t>(p->raw));
  } else if (const auto* o = std::get_if<codec::OutputStates>(&m.payload)) {
    set(config_.outputs, std::optional<std::uint8_t>(o->mask));
  } else if (const auto* g = std::get_if<codec::GenerationState>(&m.payload)) {
    set(config_.generation_enabled, std::optional<bool>(g->enabled));
  } else if (const auto* s = std::get_if<codec::Status>(&m.payload)) {
    // The status packet streams the output and generation states too: keep config current.
    set(config_.outputs, std::optional<std::uint8_t>(s->outputs));
    set(config_.generation_enabled, std::optional<bool>(s->generation_enabled));
  } else if (const auto* sn = std::get_if<codec::SerialNumber>(&m.payload)) {
    if (!info_) info_ = InfoState{};
    if (info_->serial_number != sn->serial_number) {
      info_->serial_number = sn->serial_number;
      c.info = true;
    }
  } else if (const auto* fw = std::get_if<codec::FirmwareInfo>(&m.payload)) {
    if (!info_) info_ = InfoState{};
    const auto& old = info_->firmware;
    info_->firmware_known = true;
    if (old.firmware_major != fw->firmware_major || old.firmware_minor != fw->firmware_minor ||
        old.build_year != fw->build_year || old.build_month != fw->build_month || old.build_day != fw->build_day) {
      info_->firmware = *fw;
      c.info = true;
    }
  }
  return c;
}

}  // namespace pmu::service
