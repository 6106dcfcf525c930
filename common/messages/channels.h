// LCM channel names of one snapthread session. Several sessions share one LAN by
// prefixing every channel with the session name (shared/DESIGN.md "Messages").
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace snapthread::messages {

inline constexpr const char* kDefaultSession = "SNAPTHREAD";

struct Channels {
  // Throws std::invalid_argument when `session` is empty or not [A-Za-z0-9_]+ (user
  // input, checked once at start-up).
  explicit Channels(const std::string& session = kDefaultSession);

  std::string session;
  std::string device_state;   // <SESSION>_DEVICE_STATE   device_state_t
  std::string force_model;    // <SESSION>_FORCE_MODEL    force_model_t
  std::string shape;          // <SESSION>_SHAPE          thread_shape_t
  std::string solver_status;  // <SESSION>_SOLVER_STATUS  solver_status_t
  std::string device_status;  // <SESSION>_DEVICE_STATUS  device_status_t
  std::string command;        // <SESSION>_COMMAND        command_t
  std::string command_reply;  // <SESSION>_COMMAND_REPLY  command_reply_t
};

// LCM refuses channel names longer than 63 bytes (at publish time, sending nothing);
// the longest suffixes, "_SOLVER_STATUS", "_DEVICE_STATUS" and "_COMMAND_REPLY", take 14 of them.
inline constexpr size_t kMaxSessionNameLength = 63 - 14;

// True when `session` matches [A-Za-z0-9_]+ and has at most kMaxSessionNameLength
// characters, so every channel of the session is a name LCM accepts.
bool IsValidSessionName(const std::string& session);

// The channel grammar every snapthread tool holds a channel name to: 1 to
// kMaxChannelNameLength bytes of [A-Za-z0-9_.:/-]. LCM itself takes any bytes but NUL (63 at
// most on the network, up to 999 in a log file), so a name from the network or a log is
// hostile text: outside this grammar it is shown only through EscapeForDisplay and never
// put into a path, a shell command or a script. Session names ([A-Za-z0-9_]) and the
// project's channels (<SESSION>_SHAPE, ...) are inside it.
inline constexpr size_t kMaxChannelNameLength = 63;
bool IsValidChannelName(std::string_view name);

// `text` for a terminal, a HUD, a CSV cell or a summary line: every byte outside the channel
// grammar's characters (quotes, spaces, ';', '$', '`', '|', '\\', control bytes, non-ASCII)
// becomes \xNN, so the result is printable, one line, free of shell and gnuplot syntax, and
// texts shown whole stay distinct ('\\' is \x5c). At most `max_bytes` of the input are
// shown; a longer text ends in "...[N bytes]". A valid channel name comes back unchanged.
std::string EscapeForDisplay(std::string_view text, size_t max_bytes = 128);

}  // namespace snapthread::messages
