// Which LCM provider URL a process uses.
#pragma once

#include <string>

namespace snapthread::transport {

// Loopback multicast with ttl=0: the embedded one-machine default (never leaves the host).
inline constexpr const char* kDefaultLcmUrl = "udpm://239.255.76.67:7667?ttl=0";

// The --lcm-url flag if non-empty, else the environment's LCM_DEFAULT_URL if set and
// non-empty, else kDefaultLcmUrl.
std::string ResolveLcmUrl(const std::string& flag_value);

// A one-line hint for a failed LCM start (e.g. the multicast route for udpm).
std::string LcmStartHint(const std::string& url);

}  // namespace snapthread::transport
