// snapthread-keygen: the session's keys on the server host (docs/security.md, "Roles: the
// key hierarchy"). Without a mode it makes the root key (32 random bytes, mode 0600; an
// existing one is replaced only with --force); --id prints its id; --role issues a role's
// credential from it; --rotate replaces it, keeping the previous one for the server's grace
// period; --revoke / --revoke-key-id shut one credential out; --list-revoked and --show
// print what is there. Exit status 0 done, 1 failed, 2 bad arguments.
#include <cstdio>
#include <ctime>
#include <string>

#include <CLI/CLI.hpp>

#include "app/common_flags.h"
#include "credential_commands.h"
#include "keygen_options.h"
#include "revocation_commands.h"
#include "root_key_commands.h"
#include "tool_main.h"

int main(int argc, char** argv) {
  using namespace snapthread::keygen;
  CLI::App app{"snapthread-keygen: make the session's root key (on the server host) and issue, rotate and "
               "revoke the roles' credentials"};
  snapthread::app::CommonFlags common;  // --key only: the root key
  snapthread::app::CommonFlagSet key_only;
  key_only.session = false;
  key_only.lcm_url = false;
  key_only.key_note = "; on the server host the root key FILE, beside FILE.previous and FILE.revoked";
  snapthread::app::AddCommonFlags(&app, &common, key_only);
  KeygenOptions o;
  app.add_flag("--force", o.force, "replace an existing root key (copy it to every machine) or credential file");
  app.add_flag("--id", o.show_id, "check the existing root key and print its id (compare on both machines)");
  app.add_option("--host", o.host, "ssh name of the other machine, for the printed scp commands");
  app.add_option("--role", o.role, "issue a credential: device, operator or observer (with --revoke: device or "
                                   "operator, default device)");
  app.add_option("--device", o.device, "a device credential's name: the grasp it drives (default hand)");
  app.add_option("--name", o.name, "an operator credential's name (default operator); also a device's");
  app.add_option("--expires", o.expires, "the credential's expiry: Unix seconds, or never (the default)");
  app.add_option("--expires-in", o.expires_in, "the credential's expiry from now: 30d, 12h, 90m, 3600s, 2w");
  app.add_option("--out", o.out, "the credential file to write (mode 0600)");
  app.add_flag("--rotate", o.rotate, "move the root key FILE to FILE.previous and write a new FILE");
  app.add_option("--revoke", o.revoke, "revoke every credential of device (or --role operator) NAME in FILE.revoked");
  app.add_option("--revoke-key-id", o.revoke_key_id, "revoke the credential of this key id (16 hex) in FILE.revoked");
  app.add_flag("--list-revoked", o.list_revoked, "print the entries of FILE.revoked");
  app.add_option("--show", o.show, "print a credential's role, name, expiry and ids (no secrets)");
  app.footer(
      "Examples (on the server host):\n"
      "  snapthread-keygen --role device --device left --expires-in 30d --out left.cred\n"
      "  snapthread-keygen --role operator --name alice --out alice.cred\n"
      "  snapthread-keygen --role observer --out observer.cred\n"
      "  snapthread-keygen --rotate          then re-issue, kill -HUP the server, copy, kill -HUP the devices\n"
      "  snapthread-keygen --revoke left     then kill -HUP the server\n"
      "docs/security.md, \"Issuing, rotating, revoking\", says what each writes and prints.");
  const auto run = [&]() -> int {
    for (const char* flag : {"--key", "--force", "--id", "--host", "--role", "--device", "--name", "--expires",
                             "--expires-in", "--out", "--rotate", "--revoke", "--revoke-key-id", "--list-revoked",
                             "--show"}) {
      if (app.count(flag) > 0) o.given.insert(flag);
    }
    o.key_path = common.key_path;
    const int64_t now = static_cast<int64_t>(std::time(nullptr));
    try {
      switch (SelectMode(o)) {
        case Mode::kMakeRoot: return MakeRootKey(o);
        case Mode::kShowId: return ShowRootKeyId(o);
        case Mode::kIssue: return IssueRoleCredential(o, CheckIssue(o, now), now);
        case Mode::kRotate: return RotateRootKey(o);
        case Mode::kRevoke: return Revoke(o, CheckRevoke(o), now);
        case Mode::kListRevoked: return ListRevoked(o);
        case Mode::kShow: return ShowCredential(o, now);
      }
    } catch (const UsageError& e) {
      std::fprintf(stderr, "snapthread-keygen: %s\n", e.what());
      return 2;
    }
    return 1;
  };
  // Bad arguments exit 2, every other error 1 (a bad key file is not a bad argument).
  snapthread::ToolExitCodes codes;
  codes.invalid_argument_is_bad_input = false;
  return snapthread::RunTool("snapthread-keygen", app, argc, argv, run, codes);
}
