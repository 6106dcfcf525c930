// The flags every snapthread program that joins a session shares: --session, --lcm-url,
// --key and --log-level, declared once with the project's defaults and checks so that
// each program reads them the same way and says the same thing when one is wrong.
#pragma once

#include <optional>
#include <string>
#include <string_view>

#include <CLI/CLI.hpp>

#include "auth/key_file.h"
#include "auth/key_set.h"
#include "auth/role.h"
#include "auth/session_key.h"
#include "messages/channels.h"
#include "messages/lcm_url.h"

namespace snapthread::app {

// Set from the command line by AddCommonFlags.
struct CommonFlags {
  std::string session = messages::kDefaultSession;  // channel prefix: <session>_SHAPE, ...
  std::string lcm_url;    // as given; "" = $LCM_DEFAULT_URL, else kDefaultLcmUrl (LcmUrl())
  std::string key_path;   // as given; "" = $SNAPTHREAD_KEY_FILE, else the XDG default
  std::string log_level = "info";  // spdlog's level names
  bool encrypt = false;   // --encrypt (or $SNAPTHREAD_ENCRYPT=1): seal what this program publishes
  // The --session default came from $SNAPTHREAD_SESSION (AddCommonFlags set it).
  bool session_from_environment = false;
};

// Which of the common flags a program has, and how they read there.
struct CommonFlagSet {
  bool session = true;
  bool lcm_url = true;
  bool key = true;
  bool log_level = false;
  // --encrypt: programs that publish (server, device, ctl, a viewer driving a grasp).
  bool encrypt = false;
  // A non-empty $SNAPTHREAD_SESSION is the default --session (the observers: viewer, web).
  bool session_from_environment = false;
  // The --lcm-url option's names: snapthread-logger adds lcm-logger's "-l".
  std::string lcm_url_names = "--lcm-url";
  // Appended to --key's and --session's help, e.g. "; not needed with --log".
  std::string key_note;
  std::string session_note;
};

// spdlog's level names, the values --log-level accepts.
inline constexpr const char* kLogLevels[] = {"trace", "debug", "info", "warn", "error", "critical", "off"};

// Adds the flags of `set` to `app`, writing into `flags` (whose values are the defaults).
void AddCommonFlags(CLI::App* app, CommonFlags* flags, const CommonFlagSet& set = {});

// Why `session` cannot name a session, as "bad --session <name>: expected ...", or "".
std::string SessionNameProblem(const std::string& session);

// After parsing: a session name the channels cannot carry is a bad argument. Prints
// "<program>: bad --session ..." and returns `usage_exit`; nullopt when the flags are usable.
std::optional<int> CheckCommonFlags(const CommonFlags& flags, std::string_view program, int usage_exit);

// The LCM URL to open: --lcm-url, else $LCM_DEFAULT_URL, else the loopback default, with a
// kernel receive buffer of `receive_buffer_bytes` on udpm (messages/lcm_url.h says why a
// receiver wants messages::kReceiverBufferBytes and the server and device
// messages::kServiceBufferBytes).
std::string LcmUrl(const CommonFlags& flags, int receive_buffer_bytes = messages::kReceiverBufferBytes);

// What --key names for a program playing `needed` (auth/key_set.h: the root key, or a
// credential of that role), or nullopt after printing "<program>: --key: <which file, why
// and the fix>" (a credential of another role names the role needed). `where`, if given,
// receives the file used. On success the process opens sealed messages with the keys'
// read key from now on, and seals what it publishes with --encrypt
// (auth/sealed_message.h).
std::optional<auth::KeySet> LoadKeySet(const CommonFlags& flags, auth::Role needed,
                                       std::string_view program, auth::KeyLocation* where = nullptr);

}  // namespace snapthread::app
