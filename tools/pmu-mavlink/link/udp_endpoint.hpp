#pragma once
// The UDP client endpoint: sends to one address from one socket and takes what comes back
// on it, as mavlink-router's UDP endpoints in normal mode and MAVProxy's `udpout` do. The
// socket is connect()ed to the address, so the kernel drops datagrams from anyone else.
#include "link/endpoint.hpp"
#include "link/endpoint_address.hpp"
#include "pmu/transport/unique_fd.hpp"

namespace pmu::mavlink_bridge {

class UdpEndpoint final : public Endpoint {
 public:
  // Resolves the host and opens the socket; LinkError when the host does not resolve or
  // the socket cannot be made.
  explicit UdpEndpoint(const UdpAddress& address);
  int fd() const noexcept override { return fd_.get(); }
  bool read_available(std::vector<std::uint8_t>& out) override;
  void send(const std::vector<std::uint8_t>& frame) override;
  std::string describe() const override { return description_; }

 private:
  pmu::transport::UniqueFd fd_;
  std::string description_;
};

}  // namespace pmu::mavlink_bridge
