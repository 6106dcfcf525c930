// What snapthread-keygen was asked to do: its flags, the one mode they select, and the
// checks that make a bad combination a bad argument (exit 2) before any file is touched.
#pragma once

#include <cstdint>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>

#include "auth/key_id.h"
#include "auth/role.h"

namespace snapthread::keygen {

// A bad argument: printed as "snapthread-keygen: <what>" and exit status 2.
class UsageError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

struct KeygenOptions {
  std::string key_path;  // --key: the root key ("" = SNAPTHREAD_KEY_FILE, then the default)
  std::string host = "LAB_PC";  // --host: the other machine, for the printed scp commands
  bool force = false;      // --force: replace an existing root key or credential
  bool show_id = false;    // --id
  std::string role;        // --role device|operator|observer (issuing), device|operator (revoke)
  std::string device;      // --device NAME
  std::string name;        // --name NAME
  std::string expires;     // --expires UNIX_S | never
  std::string expires_in;  // --expires-in 30d, 12h, 90m, 3600s, 2w
  std::string out;         // --out FILE
  bool rotate = false;     // --rotate
  std::string revoke;      // --revoke NAME
  std::string revoke_key_id;  // --revoke-key-id HEX16
  bool list_revoked = false;  // --list-revoked
  std::string show;        // --show FILE
  std::set<std::string> given;  // the flags given, by long name ("--role")

  bool Has(const std::string& flag) const { return given.count(flag) != 0; }
};

enum class Mode { kMakeRoot, kShowId, kIssue, kRotate, kRevoke, kListRevoked, kShow };

// The mode the flags select; throws UsageError for two modes at once or a flag that does
// not belong to the selected one.
Mode SelectMode(const KeygenOptions& options);

// What --role, --device/--name and --expires/--expires-in ask to issue, checked.
struct IssueRequest {
  auth::Role role = auth::Role::kObserver;
  std::string name;  // "" for an observer
  int64_t expires_unix_s = auth::kNeverExpires;
};
// Throws UsageError: --role server (the server holds the root key), an unknown role, no
// --out, a name for an observer, --device for an operator, an invalid name, a bad expiry.
IssueRequest CheckIssue(const KeygenOptions& options, int64_t now_unix_s);

// What --revoke/--revoke-key-id ask to revoke, as a line of the revocation list
// ("device left", "key_id 0123456789abcdef"). Throws UsageError.
struct RevokeRequest {
  std::string entry;
  std::optional<auth::Role> role;  // for a name
  std::string name;
  std::optional<auth::KeyId> key_id;
};
RevokeRequest CheckRevoke(const KeygenOptions& options);

// --expires / --expires-in as Unix seconds (kNeverExpires when neither is given). Throws
// UsageError for both, a malformed value, or a time not in the future.
int64_t ParseExpiry(const std::string& expires, const std::string& expires_in, int64_t now_unix_s);

// "2026-12-28 12:00:00 UTC (1798761600)", or "never".
std::string ExpiryText(int64_t expires_unix_s);

// The revocation list and the previous root key that belong to the root key file.
inline std::string RevokedPath(const std::string& root_path) { return root_path + ".revoked"; }
inline std::string PreviousPath(const std::string& root_path) { return root_path + ".previous"; }

}  // namespace snapthread::keygen
