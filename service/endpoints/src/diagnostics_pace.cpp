#include "pmu/endpoints/diagnostics_pace.hpp"

namespace pmu::service {

bool operator==(const ShownStatus& a, const ShownStatus& b) noexcept {
  return a.level == b.level && a.message == b.message;
}
bool operator!=(const ShownStatus& a, const ShownStatus& b) noexcept { return !(a == b); }

bool DiagnosticsPace::on_report(const std::optional<ShownStatus>& before, const ShownStatus& after,
                                TimePoint now) noexcept {
  if (!before || *before != after) return at_once(now);
  if (due_ && now < *due_) return false;
  // A report that comes within a period of its due time keeps the cadence; after a longer
  // silence the cadence starts again from this report.
  due_ = due_ && now - *due_ < period_ ? *due_ + period_ : now + period_;
  return true;
}

bool DiagnosticsPace::on_gone(TimePoint now) noexcept { return at_once(now); }

// The array written now holds every device's newest status: the next unchanged one is a period
// away.
bool DiagnosticsPace::at_once(TimePoint now) noexcept {
  due_ = now + period_;
  return true;
}

}  // namespace pmu::service
