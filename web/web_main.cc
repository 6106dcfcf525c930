// snapthread-web: watch a session from a browser. A bridge from the session's LCM channels
// to a three.js page over HTTP and WebSocket (Boost.Beast), or a replay of a recorded log.
// Exit codes: 0 after SIGINT / SIGTERM or --duration-s, 1 for bad arguments and failures.
#include <string>

#include <CLI/CLI.hpp>

#include "access_policy.h"
#include "app/command_line.h"
#include "app/common_flags.h"
#include "app/exit_codes.h"
#include "web_options.h"

#ifndef SNAPTHREAD_WEB_PAGE_DIR
#define SNAPTHREAD_WEB_PAGE_DIR ""
#endif

namespace {

constexpr const char* kProgram = "snapthread-web";
constexpr int kExitBadArguments = snapthread::app::kExitUsage;

void AddWebFlags(CLI::App* app, snapthread::web::WebOptions* o) {
  using snapthread::app::FiniteNumber;
  app->add_option("--port", o->port, "HTTP port (0: any free port, printed)")
      ->capture_default_str()->check(CLI::Range(0, 65535));
  app->add_option("--bind", o->bind, "listen address (beyond loopback the token is required)")
      ->capture_default_str();
  auto* token = app->add_option("--token", o->token,
                                "observer token pages must send as ?token= (default: none on loopback, "
                                "else a random one, printed); 16-128 of A-Z a-z 0-9 . _ ~ -");
  app->add_option("--token-file", o->token_file,
                  "read the observer token from this file (mode 0600; keeps it off the command "
                  "line, where other users see it)")
      ->excludes(token);
  app->add_option("--host-name", o->host_names,
                  "a name browsers reach this bridge by (its Host header), besides the bound "
                  "address; repeatable (e.g. --host-name labpc --host-name labpc.lab.example)");
  app->add_option("--max-pages", o->max_pages, "pages (WebSockets) open at once, at most; more get 503")
      ->capture_default_str()->check(CLI::Range(1, 4096));
  snapthread::app::CommonFlagSet common;
  common.session_from_environment = true;
  common.key_note = "; an observer credential (snapthread-keygen --role observer) or the root key; "
                    "with --log it verifies the log";
  snapthread::app::AddCommonFlags(app, &o->common, common);
  app->add_option("--log", o->log_path,
                  "replay this LCM log (snapthread-logger / lcm-logger) instead of the live session; "
                  "the page gets pause, seek and speed")
      ->check(CLI::ExistingFile);
  app->add_option("--page-dir", o->page_dir, "the built page's folder")->capture_default_str();
  app->add_option("--max-rate-hz", o->max_rate_hz, "shapes per page per second, at most")
      ->capture_default_str()->check(CLI::Range(1.0, 1000.0))->check(FiniteNumber());
  app->add_option("--duration-s", o->duration_s, "exit after this many seconds (0 = at a signal)")
      ->capture_default_str()->check(CLI::NonNegativeNumber)->check(FiniteNumber());
}

}  // namespace

int main(int argc, char** argv) {
  namespace app = snapthread::app;
  snapthread::web::WebOptions o;
  o.page_dir = SNAPTHREAD_WEB_PAGE_DIR;
  CLI::App cli{
      "snapthread-web: serves a page that draws a snapthread session (thread, grasps, force, "
      "charts of |F|, update time and residual, rates) to any number of browsers, from "
      "<SESSION>_SHAPE, _FORCE_MODEL, _SOLVER_STATUS and _DEVICE_STATUS; or replays a log "
      "(--log). Never publishes. Binds 127.0.0.1 unless --bind says otherwise; on any other "
      "address every request needs the observer token (the URL printed ends in ?token=; the "
      "page then keeps it in a cookie). Requests must name the bound address or a --host-name "
      "as their Host, and a WebSocket must come from the page itself (Origin)."};
  AddWebFlags(&cli, &o);
  if (auto code = app::ParseCommandLine(cli, argc, argv, kExitBadArguments)) return *code;
  if (auto code = app::CheckCommonFlags(o.common, kProgram, kExitBadArguments)) return *code;
  for (const std::string& name : o.host_names) {
    if (!snapthread::web::IsValidHostName(name)) {
      return app::Fail(kProgram, kExitBadArguments,
                       "bad --host-name '" + name + "' (a DNS name or an IP address)");
    }
  }
  // A receiver: a kernel buffer that rides out seconds off the CPU (lcm_url.h).
  o.lcm_url = app::LcmUrl(o.common);
  // In replay the session comes from the log unless --session (or the environment) named one.
  if (!o.log_path.empty() && cli.count("--session") == 0 && !o.common.session_from_environment) {
    o.common.session.clear();
  }
  return snapthread::web::RunWeb(o);
}
