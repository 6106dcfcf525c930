#include "app/common_flags.h"

#include <cstdio>
#include <cstdlib>
#include <exception>
#include <iterator>
#include <vector>

#include "app/command_line.h"
#include "app/exit_codes.h"
#include "auth/sealed_message.h"

namespace snapthread::app {

void AddCommonFlags(CLI::App* app, CommonFlags* flags, const CommonFlagSet& set) {
  if (set.session) {
    std::string help = "session name: the channel prefix <SESSION>_SHAPE, ... ([A-Za-z0-9_]+, at most " +
                       std::to_string(messages::kMaxSessionNameLength) + " characters";
    if (set.session_from_environment) {
      help += "; default: $SNAPTHREAD_SESSION if set";
      if (const char* s = std::getenv("SNAPTHREAD_SESSION"); s != nullptr && *s != '\0') {
        flags->session = s;
        flags->session_from_environment = true;
      }
    }
    app->add_option("--session", flags->session, help + ")" + set.session_note)->capture_default_str();
  }
  if (set.lcm_url) {
    app->add_option(set.lcm_url_names, flags->lcm_url,
                    std::string("LCM provider URL (default: $LCM_DEFAULT_URL, else ") + messages::kDefaultLcmUrl +
                        ")");
  }
  if (set.key) {
    app->add_option("--key", flags->key_path,
                    "the root key file (server host) or this program's role credential (default: $" + std::string(auth::kKeyFileEnv) +
                        ", else $XDG_CONFIG_HOME/snapthread/session.key or ~/.config/snapthread/session.key)" +
                        set.key_note);
  }
  if (set.encrypt) {
    if (const char* e = std::getenv("SNAPTHREAD_ENCRYPT"); e != nullptr && std::string_view(e) == "1") {
      flags->encrypt = true;
    }
    app->add_flag("--encrypt", flags->encrypt,
                  "seal what this program publishes under the session's read key (default: "
                  "$SNAPTHREAD_ENCRYPT=1; docs/security.md, \"Sealed payloads\")");
  }
  if (set.log_level) {
    app->add_option("--log-level", flags->log_level, "trace | debug | info | warn | error | critical | off")
        ->check(CLI::IsMember(std::vector<std::string>(std::begin(kLogLevels), std::end(kLogLevels))))
        ->capture_default_str();
  }
}

std::string SessionNameProblem(const std::string& session) {
  if (messages::IsValidSessionName(session)) return "";
  return "bad --session " + messages::EscapeForDisplay(session) + ": expected 1 to " +
         std::to_string(messages::kMaxSessionNameLength) + " characters of [A-Za-z0-9_]";
}

std::optional<int> CheckCommonFlags(const CommonFlags& flags, std::string_view program, int usage_exit) {
  if (const std::string problem = SessionNameProblem(flags.session); !problem.empty()) {
    return Fail(program, usage_exit, problem);
  }
  return std::nullopt;
}

std::string LcmUrl(const CommonFlags& flags, int receive_buffer_bytes) {
  return messages::WithReceiveBuffer(messages::ResolveLcmUrl(flags.lcm_url), receive_buffer_bytes);
}

std::optional<auth::KeySet> LoadKeySet(const CommonFlags& flags, auth::Role needed,
                                       std::string_view program, auth::KeyLocation* where) {
  try {
    const auth::KeyLocation location = auth::ResolveKeyPath(flags.key_path);
    std::optional<auth::KeySet> keys(auth::LoadKeySet(location, needed, program));
    auth::SetSealing(keys->read_key(), nullptr, flags.encrypt);
    if (where != nullptr) *where = location;
    return keys;
  } catch (const std::exception& e) {
    Fail(program, kExitFailure, std::string("--key: ") + e.what());
    return std::nullopt;
  }
}

}  // namespace snapthread::app
