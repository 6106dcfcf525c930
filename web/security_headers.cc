#include "security_headers.h"

namespace snapthread::web {

std::string ContentSecurityPolicy(std::string_view host) {
  std::string connect = "'self'";
  if (!host.empty()) {
    connect += " ws://" + std::string(host) + " wss://" + std::string(host);
  }
  // img-src data: and blob: only: the page's icon is data:, and WebGL may read blob URLs.
  return "default-src 'self'; script-src 'self'; style-src 'self'; img-src 'self' data: blob:; "
         "connect-src " + connect + "; object-src 'none'; base-uri 'none'; form-action 'none'; "
         "frame-ancestors 'none'";
}

std::vector<std::pair<std::string, std::string>> SecurityHeaders(std::string_view host) {
  return {
      {"Content-Security-Policy", ContentSecurityPolicy(host)},
      {"X-Content-Type-Options", "nosniff"},
      {"Referrer-Policy", "no-referrer"},
      {"X-Frame-Options", "DENY"},
      {"Cross-Origin-Opener-Policy", "same-origin"},
      {"Cross-Origin-Resource-Policy", "same-origin"},
  };
}

}  // namespace snapthread::web
