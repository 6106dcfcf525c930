#include "messages/lcm_url.h"

#include <algorithm>
#include <cstdlib>
#include <fstream>

namespace snapthread::messages {

std::string ResolveLcmUrl(const std::string& flag_value) {
  if (!flag_value.empty()) return flag_value;
  const char* env = std::getenv("LCM_DEFAULT_URL");
  if (env != nullptr && env[0] != '\0') return env;
  return kDefaultLcmUrl;
}

std::string WithReceiveBuffer(const std::string& url, int bytes, long rmem_max) {
  if (url.rfind("udpm://", 0) != 0 || url.find("recv_buf_size=") != std::string::npos) return url;
  long size = bytes;
  if (rmem_max > 0) size = std::min(size, rmem_max);
  if (size <= 0) return url;
  return url + (url.find('?') == std::string::npos ? "?" : "&") + "recv_buf_size=" +
         std::to_string(size);
}

std::string WithReceiveBuffer(const std::string& url, int bytes) {
  long rmem_max = 0;
  std::ifstream in("/proc/sys/net/core/rmem_max");
  if (!(in >> rmem_max)) rmem_max = 0;
  return WithReceiveBuffer(url, bytes, rmem_max);
}

std::string LcmStartHint(const std::string& url) {
  if (url.rfind("udpm://", 0) == 0) {
    return "udpm needs a multicast route; on one machine try: "
           "sudo ip route add 224.0.0.0/4 dev lo (and ip link set lo multicast on)";
  }
  return "check the LCM URL (e.g. udpm://239.255.76.67:7667?ttl=0 or memq://)";
}

}  // namespace snapthread::messages
