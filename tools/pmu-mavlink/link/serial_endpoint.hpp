#pragma once
// The serial endpoint: an autopilot's TELEM port (or a radio) at a fixed baud rate, 8N1,
// raw, no flow control, opened non-blocking.
#include "link/endpoint.hpp"
#include "link/endpoint_address.hpp"
#include "pmu/transport/unique_fd.hpp"

namespace pmu::mavlink_bridge {

class SerialEndpoint final : public Endpoint {
 public:
  // Opens and configures the device; LinkError when it cannot be opened or is not a
  // terminal (termios refuses it).
  explicit SerialEndpoint(const SerialAddress& address);
  int fd() const noexcept override { return fd_.get(); }
  bool read_available(std::vector<std::uint8_t>& out) override;
  // Written whole or not at all: a frame that does not fit the port's output buffer now
  // (the link is slower than what is sent) is dropped and counted, so no frame is ever cut.
  void send(const std::vector<std::uint8_t>& frame) override;
  std::string describe() const override { return description_; }

 private:
  pmu::transport::UniqueFd fd_;
  std::string description_;
};

}  // namespace pmu::mavlink_bridge
