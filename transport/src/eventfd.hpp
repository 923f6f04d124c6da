#pragma once
// The eventfd both buses use to make their poll fd readable for work that no socket
// announces (events raised outside drain(), frames queued by a simulated sender).

#include "pmu/transport/unique_fd.hpp"

namespace pmu::transport::detail {

// Non-blocking, close-on-exec. Throws std::system_error: only called while constructing.
UniqueFd make_eventfd();
// Makes `fd` readable. Cannot fail short of a counter overflow, which a reset every drain
// rules out.
void signal_eventfd(int fd) noexcept;
// Makes `fd` unreadable again.
void clear_eventfd(int fd) noexcept;

}  // namespace pmu::transport::detail
