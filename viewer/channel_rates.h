// Live message rates of every channel of a session (the "tool that shows live channel
// rates", `snapthread-viewer --print-rates`). Counts raw messages; no decoding, no GL.
#pragma once

#include <cstdint>
#include <map>
#include <mutex>
#include <string>

#include <lcm/lcm-cpp.hpp>

namespace snapthread::viewer {

struct ChannelCount {
  int64_t messages = 0;
  int64_t bytes = 0;
};

class ChannelRateMonitor {
 public:
  // Subscribes to every channel matching `channel_regex` (e.g. "DEMO_.*") on `lcm`.
  ChannelRateMonitor(lcm::LCM* lcm, const std::string& channel_regex);
  ~ChannelRateMonitor();
  ChannelRateMonitor(const ChannelRateMonitor&) = delete;
  ChannelRateMonitor& operator=(const ChannelRateMonitor&) = delete;

  std::map<std::string, ChannelCount> Totals() const;
  // One line per channel: "<channel> <rate Hz> <kB/s> total <n>", rates from the change
  // since the previous call over `interval_s`.
  std::string RateReport(double interval_s);

 private:
  void OnMessage(const lcm::ReceiveBuffer* rbuf, const std::string& channel);

  lcm::LCM* lcm_;
  lcm::Subscription* subscription_ = nullptr;
  mutable std::mutex mutex_;
  std::map<std::string, ChannelCount> totals_;
  std::map<std::string, ChannelCount> at_last_report_;
};

}  // namespace snapthread::viewer
