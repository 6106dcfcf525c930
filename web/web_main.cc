// snapthread-web: watch a session from a browser. A bridge from the session's LCM channels
// to a three.js page over HTTP and WebSocket (Boost.Beast), or a replay of a recorded log.
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include <CLI/CLI.hpp>

#include "access_policy.h"
#include "messages/channels.h"
#include "messages/lcm_url.h"
#include "web_options.h"

#ifndef SNAPTHREAD_WEB_PAGE_DIR
#define SNAPTHREAD_WEB_PAGE_DIR ""
#endif

int main(int argc, char** argv) {
  snapthread::web::WebOptions o;
  o.page_dir = SNAPTHREAD_WEB_PAGE_DIR;
  if (const char* s = std::getenv("SNAPTHREAD_SESSION"); s != nullptr && *s != '\0') o.session = s;
  CLI::App app{
      "snapthread-web: serves a page that draws a snapthread session (thread, grasps, force, "
      "charts of |F|, update time and residual, rates) to any number of browsers, from "
      "<SESSION>_SHAPE, _FORCE_MODEL, _SOLVER_STATUS and _DEVICE_STATUS; or replays a log "
      "(--log). Never publishes. Binds 127.0.0.1 unless --bind says otherwise; on any other "
      "address every request needs the observer token (the URL printed ends in ?token=; the "
      "page then keeps it in a cookie). Requests must name the bound address or a --host-name "
      "as their Host, and a WebSocket must come from the page itself (Origin)."};
  app.add_option("--port", o.port, "HTTP port (0: any free port, printed)")
      ->capture_default_str()->check(CLI::Range(0, 65535));
  app.add_option("--bind", o.bind, "listen address (beyond loopback the token is required)")
      ->capture_default_str();
  auto* token = app.add_option("--token", o.token,
                 "observer token pages must send as ?token= (default: none on loopback, "
                 "else a random one, printed); 16-128 of A-Z a-z 0-9 . _ ~ -");
  app.add_option("--token-file", o.token_file,
                 "read the observer token from this file (mode 0600; keeps it off the command "
                 "line, where other users see it)")
      ->excludes(token);
  app.add_option("--host-name", o.host_names,
                 "a name browsers reach this bridge by (its Host header), besides the bound "
                 "address; repeatable (e.g. --host-name labpc --host-name labpc.lab.example)");
  app.add_option("--max-pages", o.max_pages, "pages (WebSockets) open at once, at most; more get 503")
      ->capture_default_str()->check(CLI::Range(1, 4096));
  app.add_option("--session", o.session, "session name (channel prefix; env SNAPTHREAD_SESSION)")
      ->capture_default_str();
  app.add_option("--lcm-url", o.lcm_url,
                 "LCM URL (default: env LCM_DEFAULT_URL, else udpm://239.255.76.67:7667?ttl=0)");
  app.add_option("--key", o.key_path,
                 "session key file (default: $SNAPTHREAD_KEY_FILE, else "
                 "$XDG_CONFIG_HOME/snapthread/session.key); not needed with --log");
  app.add_option("--log", o.log_path,
                 "replay this LCM log (snapthread-logger / lcm-logger) instead of the live session; "
                 "the page gets pause, seek and speed")
      ->check(CLI::ExistingFile);
  app.add_option("--page-dir", o.page_dir, "the built page's folder")->capture_default_str();
  app.add_option("--max-rate-hz", o.max_rate_hz, "shapes per page per second, at most")
      ->capture_default_str()->check(CLI::Range(1.0, 1000.0));
  app.add_option("--duration-s", o.duration_s, "exit after this many seconds (0 = at a signal)")
      ->capture_default_str()->check(CLI::NonNegativeNumber);
  CLI11_PARSE(app, argc, argv);
  // CLI11's range checks let "nan" through.
  if (!std::isfinite(o.max_rate_hz) || !std::isfinite(o.duration_s)) {
    std::fprintf(stderr, "snapthread-web: --max-rate-hz and --duration-s must be finite numbers\n");
    return 1;
  }
  if (!snapthread::messages::IsValidSessionName(o.session)) {
    std::fprintf(stderr, "snapthread-web: bad --session '%s' (expected [A-Za-z0-9_]+)\n",
                 o.session.c_str());
    return 1;
  }
  for (const std::string& name : o.host_names) {
    if (!snapthread::web::IsValidHostName(name)) {
      std::fprintf(stderr, "snapthread-web: bad --host-name '%s' (a DNS name or an IP address)\n",
                   name.c_str());
      return 1;
    }
  }
  // A receiver: a kernel buffer that rides out seconds off the CPU (lcm_url.h).
  o.lcm_url = snapthread::messages::WithReceiveBuffer(snapthread::messages::ResolveLcmUrl(o.lcm_url));
  // In replay the session comes from the log unless --session was given.
  if (!o.log_path.empty() && app.count("--session") == 0 && std::getenv("SNAPTHREAD_SESSION") == nullptr) {
    o.session.clear();
  }
  return snapthread::web::RunWeb(o);
}
