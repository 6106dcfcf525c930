// The headers every response of the bridge carries, whatever its status: a
// Content-Security-Policy under which the page runs only its own script file (no inline
// script, no eval, no handler attributes: text that reached the DOM as markup still could
// not run), loads only its own files, connects only to its own WebSocket and cannot be
// framed; no MIME sniffing; no Referer (the address could carry the token).
#pragma once

#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace snapthread::web {

// `host`: the request's accepted Host (access_policy.h), "" when it was refused. The
// WebSocket is allowed at ws:// and wss:// of that host ('self' covers them in current
// browsers, older ones need them named).
std::string ContentSecurityPolicy(std::string_view host);

std::vector<std::pair<std::string, std::string>> SecurityHeaders(std::string_view host);

}  // namespace snapthread::web
