// snapthread-keygen: makes the session key (32 random bytes, mode 0600) and says how to
// copy it to the second machine (docs/security.md). Refuses to replace a key without
// --force: every machine of the session holds a copy and would stop being trusted.
#include <cstdio>
#include <string>

#include <CLI/CLI.hpp>

#include "app/common_flags.h"
#include "auth/key_file.h"
#include "tool_main.h"

int main(int argc, char** argv) {
  using namespace snapthread::auth;
  CLI::App app{"snapthread-keygen: make the session key shared by the server, device and viewers"};
  snapthread::app::CommonFlags common;  // --key only
  snapthread::app::CommonFlagSet key_only;
  key_only.session = false;
  key_only.lcm_url = false;
  snapthread::app::AddCommonFlags(&app, &common, key_only);
  std::string host = "LAB_PC";
  bool force = false, show_id = false;
  app.add_flag("--force", force, "replace an existing key (copy the new one to every machine)");
  app.add_flag("--id", show_id, "check the existing key and print its id (compare on both machines)");
  app.add_option("--host", host, "ssh name of the other machine, for the printed scp command");
  const auto run = [&]() -> int {
    const KeyLocation where = ResolveKeyPath(common.key_path);
    if (show_id) {
      std::printf("%s: key id %s (%s)\n", where.path.c_str(), LoadKey(where).Id().c_str(),
                  where.origin.c_str());
      return 0;
    }
    WriteNewKey(where, force);
    const std::string id = LoadKey(where).Id();  // reads it back: mode and size as checked
    std::printf("snapthread-keygen: wrote a new session key to %s (mode 0600, key id %s)\n",
                where.path.c_str(), id.c_str());
    std::printf("Copy it to the other machine (scp -p keeps mode 0600):\n");
    std::printf("  ssh %s 'mkdir -p -m 700 ~/.config/snapthread'\n", host.c_str());
    std::printf("  scp -p %s %s:.config/snapthread/session.key\n", where.path.c_str(), host.c_str());
    std::printf("Check the copy: ssh %s snapthread-keygen --id   (must print key id %s)\n",
                host.c_str(), id.c_str());
    return 0;
  };
  // Bad arguments exit 2, every other error 1 (a bad key file is not a bad argument).
  snapthread::ToolExitCodes codes;
  codes.invalid_argument_is_bad_input = false;
  return snapthread::RunTool("snapthread-keygen", app, argc, argv, run, codes);
}
