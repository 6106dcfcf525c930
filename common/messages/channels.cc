#include "messages/channels.h"

#include <stdexcept>

namespace snapthread::transport {

bool IsValidSessionName(const std::string& session) {
  if (session.empty() || session.size() > kMaxSessionNameLength) return false;
  for (char c : session) {
    const bool ok = (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') ||
                    (c >= '0' && c <= '9') || c == '_';
    if (!ok) return false;
  }
  return true;
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
}

}  // namespace snapthread::transport
