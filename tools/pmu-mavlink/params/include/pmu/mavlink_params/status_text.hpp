#pragma once
// A reason as STATUSTEXT: the text cut into the message's 50-byte chunks (the extension's id
// and chunk_seq tie them together; a text that fits one message goes alone, id 0), at most
// kMaxChunks of them (the rest cut, marked "..."), bytes outside printable ASCII as '?'. The
// reasons come from the service and may quote a peer's text: a ground station shows them.

#include <cstdint>
#include <string_view>
#include <vector>

#include "pmu/mavlink/messages.hpp"

namespace pmu::mavlink_params {

inline constexpr std::size_t kMaxChunks = 4;

// `id` names a multi-chunk text (not 0); the caller counts it up per text it sends.
std::vector<mavlink::Statustext> status_text(std::uint8_t severity, std::string_view text, std::uint16_t id);

}  // namespace pmu::mavlink_params
