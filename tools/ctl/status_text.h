// What snapthread-ctl prints from the network: a reply's text, and: one authenticated SOLVER_STATUS as "name: value"
// lines. Names from the network (scene, method, knot) are shown only through
// messages::EscapeForDisplay, free text through TerminalText.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

#include "snapthread/solver_status_t.hpp"

namespace snapthread::ctl {

// A server's text (a command's reply) for a terminal: printable ASCII stays as it is,
// every other byte (control bytes, escape sequences, non-ASCII, and '\\' itself) is
// shown as messages::EscapeForDisplay shows it (\xNN); at most `max_bytes` are shown.
std::string TerminalText(std::string_view text, size_t max_bytes);

// "regular", "near fold", "snapped", "invalid", "snapping" (force_model_t.STATUS_*).
std::string StatusName(int8_t status);

std::string StatusText(const solver_status_t& status);

}  // namespace snapthread::ctl
