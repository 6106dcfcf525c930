// The roles of a session and the names of their credentials (docs/security.md, "Roles:
// the key hierarchy"). The server host holds the root key; a device drives one grasp; an
// observer (viewer, web page, review tools) only verifies and reads; an operator sends
// commands.
#pragma once

#include <cstdint>
#include <optional>
#include <string_view>

namespace snapthread::auth {

enum class Role { kServer, kDevice, kObserver, kOperator };

// "server", "device", "observer", "operator".
std::string_view RoleToString(Role role);
// The role of one of those words; std::nullopt for anything else (exact, lower case).
std::optional<Role> RoleFromString(std::string_view text);

// Devices and operators are named: 1 to kMaxRoleNameBytes of [A-Za-z0-9_-], so a name can
// be written in a file line, a channel or a message without quoting or escaping.
inline constexpr std::size_t kMaxRoleNameBytes = 32;
bool IsValidRoleName(std::string_view name);
// Whether a credential of this role carries a name (device, operator).
bool RoleIsNamed(Role role);

// A credential's expiry in Unix seconds; kNeverExpires for none.
inline constexpr int64_t kNeverExpires = 0;
// Whether a credential expiring at `expires_unix_s` is expired at `now_unix_s` (it is
// valid up to, not including, its expiry second).
bool IsExpired(int64_t expires_unix_s, int64_t now_unix_s);

}  // namespace snapthread::auth
