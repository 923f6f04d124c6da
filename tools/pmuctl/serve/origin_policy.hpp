#pragma once
// Which web pages may open a `pmuctl serve` connection (docs/interface.md, "Live: Foxglove
// WebSocket"). A browser lets any page open a WebSocket to any address, and sends the page's
// origin in the handshake's Origin header; the server is what refuses a page it does not know,
// so a site visited in the same browser cannot read the vehicle's topics. Pure.
//
//   default: a client that sends no Origin (a native tool; a browser always sends one),
//            https://app.foxglove.dev, https://studio.foxglove.dev (the Foxglove app),
//            file:// (the Foxglove and Lichtblick desktop apps: Electron pages loaded from
//            files), http(s)://localhost, 127.0.0.1 and [::1] on any port (a local page,
//            Lichtblick's web app served on this host)
//   --allow-origin https://viz.example.com:8443 -> also that origin, exactly
//   --allow-origin '*'                          -> every origin, null included
//   refused by default: "null" (a sandboxed page), any other site
//
// Origins compare as browsers send them: lower case, the scheme's default port left out
// (an --allow-origin of https://x:443 is https://x).

#include <string>
#include <string_view>
#include <vector>

namespace pmu::tools {

struct OriginPolicy {
  bool any = false;                // --allow-origin '*'
  std::vector<std::string> exact;  // from --allow-origin, normalised: "https://viz.example.com:8443"
};

// One --allow-origin value into `policy`; "" or what is wrong, naming the option.
std::string add_allowed_origin(const std::string& text, OriginPolicy& policy);

// `origin`: the handshake's Origin header, "" when it has none.
bool origin_allowed(const OriginPolicy& policy, std::string_view origin);

}  // namespace pmu::tools
