// snapthread-web's options (the command line; web_main.cc documents each flag).
#pragma once

#include <string>
#include <vector>

#include "app/common_flags.h"

namespace snapthread::web {

struct WebOptions {
  app::CommonFlags common;             // --session (env SNAPTHREAD_SESSION; "" in replay: the log's), --lcm-url, --key
  std::string lcm_url;                 // the URL opened: app::LcmUrl(common)
  std::string bind = "127.0.0.1";      // listen address
  int port = 7000;                     // 0: the kernel picks one (printed)
  std::string token;                   // observer token ("" = generated when not loopback)
  std::string token_file;              // read the token from this file instead (0600)
  std::vector<std::string> host_names; // names the page may be reached by (Host), besides the address
  int max_pages = 16;                  // WebSocket pages open at once, at most
  std::string log_path;                // replay this log instead of the live session
  std::string page_dir;                // the built page (default: the build's web/page)
  double max_rate_hz = 60.0;           // shapes and force models per page, at most
  double duration_s = 0.0;             // exit after this long (0: at SIGINT / SIGTERM)
};

// Runs the bridge until a signal or the duration; returns the exit code (0 ok, 1 set-up
// failed, with a message on stderr).
int RunWeb(WebOptions options);

}  // namespace snapthread::web
