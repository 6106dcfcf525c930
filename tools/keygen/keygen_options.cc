#include "keygen_options.h"

#include <ctime>
#include <string>
#include <vector>

namespace snapthread::keygen {
namespace {

using auth::Role;

// The flags each mode accepts beyond --key.
struct ModeFlags {
  Mode mode;
  const char* selector;  // what the messages call the mode
  std::vector<std::string> flags;
};
const std::vector<ModeFlags>& AllModeFlags() {
  static const std::vector<ModeFlags> modes = {
      {Mode::kMakeRoot, "making the root key", {"--force", "--host"}},
      {Mode::kShowId, "--id", {"--id"}},
      {Mode::kIssue, "--role", {"--role", "--device", "--name", "--expires", "--expires-in", "--out", "--force", "--host"}},
      {Mode::kRotate, "--rotate", {"--rotate"}},
      {Mode::kRevoke, "--revoke", {"--revoke", "--revoke-key-id", "--role"}},
      {Mode::kListRevoked, "--list-revoked", {"--list-revoked"}},
      {Mode::kShow, "--show", {"--show"}},
  };
  return modes;
}

// 1 to 13 decimal digits (no sign, no leading zero): a count that cannot overflow below.
bool ParseCount(const std::string& text, int64_t* value) {
  if (text.empty() || text.size() > 13 || text[0] == '0') return false;
  int64_t v = 0;
  for (const char c : text) {
    if (c < '0' || c > '9') return false;
    v = v * 10 + (c - '0');
  }
  *value = v;
  return true;
}

}  // namespace

Mode SelectMode(const KeygenOptions& o) {
  std::vector<Mode> chosen;
  if (o.Has("--id")) chosen.push_back(Mode::kShowId);
  if (o.Has("--revoke") || o.Has("--revoke-key-id")) {
    chosen.push_back(Mode::kRevoke);
  } else if (o.Has("--role")) {
    chosen.push_back(Mode::kIssue);
  }
  if (o.rotate) chosen.push_back(Mode::kRotate);
  if (o.list_revoked) chosen.push_back(Mode::kListRevoked);
  if (o.Has("--show")) chosen.push_back(Mode::kShow);
  if (chosen.size() > 1) {
    throw UsageError("choose one of --role, --rotate, --revoke/--revoke-key-id, --list-revoked, --show and --id");
  }
  const Mode mode = chosen.empty() ? Mode::kMakeRoot : chosen.front();
  for (const ModeFlags& m : AllModeFlags()) {
    if (m.mode != mode) continue;
    for (const std::string& flag : o.given) {
      bool allowed = flag == "--key";
      for (const std::string& f : m.flags) allowed = allowed || f == flag;
      if (!allowed) throw UsageError(flag + " does not go with " + m.selector + " (see --help)");
    }
  }
  return mode;
}

int64_t ParseExpiry(const std::string& expires, const std::string& expires_in, int64_t now_unix_s) {
  if (!expires.empty() && !expires_in.empty()) throw UsageError("give --expires or --expires-in, not both");
  if (!expires.empty()) {
    if (expires == "never" || expires == "0") return auth::kNeverExpires;
    int64_t at = 0;
    if (!ParseCount(expires, &at)) {
      throw UsageError("--expires '" + expires + "': expected Unix seconds (e.g. 1798761600) or never");
    }
    if (at <= now_unix_s) {
      throw UsageError("--expires " + expires + " is not in the future (now " + std::to_string(now_unix_s) + ")");
    }
    return at;
  }
  if (expires_in.empty()) return auth::kNeverExpires;
  static const std::pair<char, int64_t> kUnits[] = {{'s', 1}, {'m', 60}, {'h', 3600}, {'d', 86400}, {'w', 604800}};
  int64_t count = 0;
  for (const auto& [unit, seconds] : kUnits) {
    if (expires_in.back() == unit && ParseCount(expires_in.substr(0, expires_in.size() - 1), &count)) {
      return now_unix_s + count * seconds;
    }
  }
  throw UsageError("--expires-in '" + expires_in + "': expected a positive count and a unit s, m, h, d or w (30d, 12h)");
}

std::string ExpiryText(int64_t expires_unix_s) {
  if (expires_unix_s == auth::kNeverExpires) return "never";
  const std::time_t t = static_cast<std::time_t>(expires_unix_s);
  std::tm tm{};
  char text[32] = "?";
  if (gmtime_r(&t, &tm) != nullptr) std::strftime(text, sizeof text, "%Y-%m-%d %H:%M:%S UTC", &tm);
  return std::string(text) + " (" + std::to_string(expires_unix_s) + ")";
}

IssueRequest CheckIssue(const KeygenOptions& o, int64_t now_unix_s) {
  const std::optional<Role> role = auth::RoleFromString(o.role);
  if (!role) throw UsageError("--role '" + o.role + "': expected device, operator or observer");
  if (*role == Role::kServer) {
    throw UsageError("--role server: the server takes no credential, it holds the root key itself "
                     "(start snapthread-server with --key " + (o.key_path.empty() ? std::string("FILE") : o.key_path) +
                     " on the server host)");
  }
  if (o.out.empty()) throw UsageError("--role needs --out FILE: where to write the credential");
  IssueRequest request;
  request.role = *role;
  if (*role == Role::kObserver) {
    if (o.Has("--device") || o.Has("--name")) throw UsageError("an observer credential has no name (leave out --device and --name)");
  } else if (*role == Role::kOperator) {
    if (o.Has("--device")) throw UsageError("--device names a device; an operator's name is --name NAME");
    request.name = o.Has("--name") ? o.name : "operator";
  } else {
    if (o.Has("--device") && o.Has("--name")) throw UsageError("give --device NAME or --name NAME, not both");
    // A one-grasp scene's grasp is called "hand".
    request.name = o.Has("--device") ? o.device : o.Has("--name") ? o.name : "hand";
  }
  if (auth::RoleIsNamed(*role) && !auth::IsValidRoleName(request.name)) {
    throw UsageError("'" + request.name + "' is not a valid " + o.role + " name: 1 to " +
                     std::to_string(auth::kMaxRoleNameBytes) + " of A-Z a-z 0-9 _ -");
  }
  request.expires_unix_s = ParseExpiry(o.expires, o.expires_in, now_unix_s);
  return request;
}

RevokeRequest CheckRevoke(const KeygenOptions& o) {
  if (o.Has("--revoke") && o.Has("--revoke-key-id")) throw UsageError("give --revoke or --revoke-key-id, not both");
  RevokeRequest request;
  if (o.Has("--revoke-key-id")) {
    if (o.Has("--role")) throw UsageError("--role goes with --revoke NAME; a key id names its credential alone");
    request.key_id = auth::KeyIdFromHex(o.revoke_key_id);
    if (!request.key_id) {
      throw UsageError("--revoke-key-id '" + o.revoke_key_id + "': expected the 16 hex digits of a key id "
                       "(the credential's key_id line, or snapthread-keygen --show FILE)");
    }
    request.entry = "key_id " + auth::KeyIdToHex(*request.key_id);
    return request;
  }
  const std::optional<Role> role = o.Has("--role") ? auth::RoleFromString(o.role) : Role::kDevice;
  if (!role) throw UsageError("--role '" + o.role + "': a revoked name is a device's or an operator's");
  if (*role == Role::kObserver || *role == Role::kServer) {
    throw UsageError("--role " + o.role + " cannot be revoked by name (only devices and operators hold their own "
                     "key); to shut out observers or the server's key, rotate the root key (--rotate)");
  }
  if (!auth::IsValidRoleName(o.revoke)) {
    throw UsageError("--revoke '" + o.revoke + "': a name is 1 to " + std::to_string(auth::kMaxRoleNameBytes) +
                     " of A-Z a-z 0-9 _ -");
  }
  request.role = *role;
  request.name = o.revoke;
  request.entry = std::string(auth::RoleToString(*role)) + " " + o.revoke;
  return request;
}

}  // namespace snapthread::keygen
