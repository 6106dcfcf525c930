#include "access_policy.h"

#include <algorithm>
#include <cctype>

#include "observer_token.h"

namespace snapthread::web {
namespace {

std::string Lower(std::string_view s) {
  std::string out(s);
  std::transform(out.begin(), out.end(), out.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return out;
}

std::string_view Trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

// Splits "name:port", "[v6]:port", "name" or "[v6]"; false when malformed.
bool SplitHost(std::string_view host, std::string_view* name, std::string_view* port) {
  *port = {};
  if (!host.empty() && host.front() == '[') {
    const size_t close = host.find(']');
    if (close == std::string_view::npos) return false;
    *name = host.substr(0, close + 1);
    const std::string_view rest = host.substr(close + 1);
    if (rest.empty()) return true;
    if (rest.front() != ':') return false;
    *port = rest.substr(1);
    return !port->empty();
  }
  const size_t colon = host.find(':');
  if (colon == std::string_view::npos) {
    *name = host;
    return true;
  }
  if (host.find(':', colon + 1) != std::string_view::npos) return false;  // bare IPv6
  *name = host.substr(0, colon);
  *port = host.substr(colon + 1);
  return !port->empty();
}

AccessVerdict Refuse(int status, std::string why) {
  AccessVerdict v;
  v.kind = AccessVerdict::Kind::kRefuse;
  v.status = status;
  v.why = std::move(why);
  return v;
}

}  // namespace

bool IsValidHostName(std::string_view name) {
  if (name.empty() || name.size() > 253) return false;
  if (name.front() == '[') {
    return name.size() > 2 && name.back() == ']' &&
           std::all_of(name.begin() + 1, name.end() - 1, [](char c) {
             return std::isxdigit(static_cast<unsigned char>(c)) || c == ':' || c == '.';
           });
  }
  return std::all_of(name.begin(), name.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '-';
  });
}

std::string TokenCookieName(unsigned short port) { return "snapthread_token_" + std::to_string(port); }

std::string CookieValue(std::string_view header, std::string_view name) {
  while (!header.empty()) {
    const size_t semi = header.find(';');
    const std::string_view pair = Trim(header.substr(0, semi));
    const size_t eq = pair.find('=');
    if (eq != std::string_view::npos && Trim(pair.substr(0, eq)) == name) {
      return std::string(Trim(pair.substr(eq + 1)));
    }
    if (semi == std::string_view::npos) break;
    header.remove_prefix(semi + 1);
  }
  return "";
}

bool HostAllowed(const AccessConfig& config, std::string_view host, const std::string& local_address,
                 bool local_is_loopback) {
  const std::string lower = Lower(Trim(host));
  std::string_view name, port;
  if (lower.empty() || !SplitHost(lower, &name, &port) || name.empty()) return false;
  if (port.empty()) {
    if (config.port != 80) return false;  // a browser leaves out only the default port
  } else {
    if (port.size() > 5 || !std::all_of(port.begin(), port.end(), [](char c) { return c >= '0' && c <= '9'; })) {
      return false;
    }
    if (std::stoi(std::string(port)) != config.port) return false;
  }
  if (name == Lower(local_address)) return true;
  if (local_is_loopback && name == "localhost") return true;
  return std::any_of(config.host_names.begin(), config.host_names.end(),
                     [&](const std::string& n) { return Lower(n) == name; });
}

bool OriginMatches(std::string_view origin, std::string_view host) {
  const std::string o = Lower(Trim(origin));
  const std::string h = Lower(host);
  return !h.empty() && (o == "http://" + h || o == "https://" + h);
}

AccessVerdict DecideAccess(const AccessConfig& config, const RequestFacts& request,
                           const std::function<bool(std::string_view path)>& page_exists) {
  if (!HostAllowed(config, request.host, request.local_address, request.local_is_loopback)) {
    return Refuse(403,
                  "403: the Host header does not name this bridge (its address, or a name given "
                  "with --host-name)\n");
  }
  const std::string host = Lower(Trim(request.host));
  AccessVerdict serve;
  serve.kind = AccessVerdict::Kind::kServe;
  serve.host = host;
  if (!config.token.empty()) {
    const std::string query = QueryParameter(request.target, "token");
    if (!query.empty()) {
      if (!TokenMatches(query, config.token)) {
        return Refuse(401, "401: wrong observer token: open the URL snapthread-web printed\n");
      }
      if (!request.upgrade) {
        // The token moves into a cookie, and the browser to the address without it.
        AccessVerdict v;
        v.kind = AccessVerdict::Kind::kRedirect;
        v.host = host;
        const std::string_view path = TargetPath(request.target);
        v.location = page_exists(path) ? std::string(path) : "/";
        v.set_cookie = TokenCookieName(config.port) + "=" + config.token +
                       "; Path=/; HttpOnly; SameSite=Strict";
        return v;
      }
    } else if (!TokenMatches(CookieValue(request.cookie, TokenCookieName(config.port)), config.token)) {
      return Refuse(401,
                    "401: this page needs the observer token: open the URL snapthread-web printed "
                    "(it ends in ?token=...)\n");
    }
  }
  if (request.upgrade && !OriginMatches(request.origin, host)) {
    return Refuse(403, "403: a WebSocket of this bridge opens only from its own page (Origin)\n");
  }
  return serve;
}

}  // namespace snapthread::web
