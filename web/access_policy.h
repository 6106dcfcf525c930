// Who may ask the bridge for what: the checks every HTTP request and WebSocket upgrade
// passes before anything is served, as pure logic (no sockets) so that each case is tested
// alone. In order:
//   1. Host must name the address the connection arrived on (the bound address; with a
//      wildcard bind the interface's), "localhost" on loopback, or a name given with
//      --host-name, with the bound port. Anything else is 403: a page of another site
//      whose name an attacker made resolve to this address (DNS rebinding) names its own
//      host, not ours.
//   2. When a token is required (beyond loopback, or --token given): the token, from
//      ?token= or from the cookie the bridge set. A page load with the right ?token= is
//      answered with a redirect to the same page without it, setting the token as an
//      HttpOnly, SameSite=Strict cookie, so the token leaves the address bar (and the
//      history) and every later request of the browser, the WebSocket included, carries
//      it. Missing or wrong: 401.
//   3. A WebSocket upgrade must come with an Origin that is this very page
//      (http(s)://<Host>): a page of any other origin cannot open the feed with the
//      observer's cookie (403).
// Tokens are compared in constant time (observer_token.h).
#pragma once

#include <functional>
#include <string>
#include <string_view>
#include <vector>

namespace snapthread::web {

struct AccessConfig {
  std::string token;                    // "" = no token required
  std::vector<std::string> host_names;  // --host-name (any case; compared lowercase)
  unsigned short port = 0;              // the bound port
};

// The parts of a request the checks read. `local_address` is where the connection
// arrived: "127.0.0.1", "10.1.2.3" or "[fe80::1]" (an IPv4-mapped IPv6 address written
// as IPv4), `local_is_loopback` whether it is a loopback address.
struct RequestFacts {
  std::string_view target;  // "/app.js?token=..."
  std::string_view host;    // the Host header ("" when absent)
  std::string_view origin;  // the Origin header ("" when absent)
  std::string_view cookie;  // the Cookie header ("" when absent)
  bool upgrade = false;     // a WebSocket upgrade
  std::string local_address;
  bool local_is_loopback = false;
};

struct AccessVerdict {
  enum class Kind { kServe, kRedirect, kRefuse };
  Kind kind = Kind::kRefuse;
  int status = 403;         // with kRefuse: 401 or 403
  std::string why;          // with kRefuse: the body (names what was wrong)
  std::string location;     // with kRedirect: a path on this host ("/", "/app.js")
  std::string set_cookie;   // with kRedirect: the Set-Cookie value
  std::string host;         // the accepted Host, lowercase ("" unless checked and accepted)
};

// Whether `name` may be a --host-name: a DNS name or IPv4 address (A-Z a-z 0-9 . -), or
// an IPv6 address in brackets; at most 253 characters. Host names go into the
// Content-Security-Policy header, so nothing else is let in.
bool IsValidHostName(std::string_view name);

// The name of the cookie that carries the token: per port, so two bridges on one host
// keep their own.
std::string TokenCookieName(unsigned short port);

// The value of cookie `name` in a Cookie header ("a=1; b=2"), "" when absent.
std::string CookieValue(std::string_view header, std::string_view name);

// Whether `host` (a Host header) names this bridge: see the file comment.
bool HostAllowed(const AccessConfig& config, std::string_view host, const std::string& local_address,
                 bool local_is_loopback);

// Whether a WebSocket's `origin` is the page served from `host` (the accepted Host).
bool OriginMatches(std::string_view origin, std::string_view host);

// The checks 1-3 above. `page_exists(path)` says whether a redirect may go to that path
// (else it goes to "/"): the redirect never sends the browser anywhere but a page file.
AccessVerdict DecideAccess(const AccessConfig& config, const RequestFacts& request,
                           const std::function<bool(std::string_view path)>& page_exists);

}  // namespace snapthread::web
