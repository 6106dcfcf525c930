#include "auth/role.h"

namespace snapthread::auth {

std::string_view RoleToString(Role role) {
  switch (role) {
    case Role::kServer: return "server";
    case Role::kDevice: return "device";
    case Role::kObserver: return "observer";
    case Role::kOperator: return "operator";
  }
  return "unknown";
}

std::optional<Role> RoleFromString(std::string_view text) {
  for (const Role role : {Role::kServer, Role::kDevice, Role::kObserver, Role::kOperator}) {
    if (text == RoleToString(role)) return role;
  }
  return std::nullopt;
}

bool IsValidRoleName(std::string_view name) {
  if (name.empty() || name.size() > kMaxRoleNameBytes) return false;
  for (const char c : name) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                    c == '_' || c == '-';
    if (!ok) return false;
  }
  return true;
}

bool RoleIsNamed(Role role) { return role == Role::kDevice || role == Role::kOperator; }

bool IsExpired(int64_t expires_unix_s, int64_t now_unix_s) {
  return expires_unix_s != kNeverExpires && now_unix_s >= expires_unix_s;
}

}  // namespace snapthread::auth
