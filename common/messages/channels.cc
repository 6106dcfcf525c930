#include "messages/channels.h"

#include <stdexcept>

namespace snapthread::messages {

bool IsValidSessionName(const std::string& session) {
  if (session.empty() || session.size() > kMaxSessionNameLength) return false;
  for (char c : session) {
    const bool ok = (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') ||
                    (c >= '0' && c <= '9') || c == '_';
    if (!ok) return false;
  }
  return true;
}

namespace {

bool IsChannelChar(unsigned char c) {
  return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') ||
         c == '_' || c == '.' || c == ':' || c == '/' || c == '-';
}

}  // namespace

bool IsValidChannelName(std::string_view name) {
  if (name.empty() || name.size() > kMaxChannelNameLength) return false;
  for (char c : name) {
    if (!IsChannelChar(static_cast<unsigned char>(c))) return false;
  }
  return true;
}

std::string EscapeForDisplay(std::string_view text, size_t max_bytes) {
  static constexpr char kHex[] = "0123456789abcdef";
  std::string out;
  const size_t shown = text.size() < max_bytes ? text.size() : max_bytes;
  out.reserve(shown + 16);
  for (size_t i = 0; i < shown; ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (IsChannelChar(c)) {
      out += static_cast<char>(c);
    } else {
      out += "\\x";
      out += kHex[c >> 4];
      out += kHex[c & 15];
    }
  }
  if (shown < text.size()) out += "...[" + std::to_string(text.size()) + " bytes]";
  return out;
}

Channels::Channels(const std::string& session_name) : session(session_name) {
  if (!IsValidSessionName(session_name)) {
    throw std::invalid_argument("invalid session name '" + session_name +
                                "': expected 1 to " + std::to_string(kMaxSessionNameLength) +
                                " characters of [A-Za-z0-9_] (LCM channel names are at most 63 bytes)");
  }
  device_state = session + "_DEVICE_STATE";
  force_model = session + "_FORCE_MODEL";
  shape = session + "_SHAPE";
  solver_status = session + "_SOLVER_STATUS";
  device_status = session + "_DEVICE_STATUS";
  command = session + "_COMMAND";
  command_reply = session + "_COMMAND_REPLY";
}

}  // namespace snapthread::messages
