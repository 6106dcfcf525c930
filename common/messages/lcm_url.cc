#include "messages/lcm_url.h"

#include <cstdlib>

namespace snapthread::transport {

std::string ResolveLcmUrl(const std::string& flag_value) {
  if (!flag_value.empty()) return flag_value;
  const char* env = std::getenv("LCM_DEFAULT_URL");
  if (env != nullptr && env[0] != '\0') return env;
  return kDefaultLcmUrl;
}

std::string LcmStartHint(const std::string& url) {
  if (url.rfind("udpm://", 0) == 0) {
    return "udpm needs a multicast route; on one machine try: "
           "sudo ip route add 224.0.0.0/4 dev lo (and ip link set lo multicast on)";
  }
  return "check the LCM URL (e.g. udpm://239.255.76.67:7667?ttl=0 or memq://)";
}

}  // namespace snapthread::transport
