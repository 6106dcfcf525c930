#include "channel_rates.h"

#include "messages/channels.h"
#include "messages/subscribe.h"

#include <cstdio>

namespace snapthread::viewer {

ChannelRateMonitor::ChannelRateMonitor(lcm::LCM* lcm, const std::string& channel_regex)
    : lcm_(lcm) {
  subscription_ = messages::Subscribe<&ChannelRateMonitor::OnMessage>(lcm_, channel_regex, this);
}

ChannelRateMonitor::~ChannelRateMonitor() {
  if (subscription_ != nullptr) lcm_->unsubscribe(subscription_);
}

void ChannelRateMonitor::OnMessage(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
  std::lock_guard<std::mutex> lock(mutex_);
  ChannelCount& c = totals_[channel];
  c.messages++;
  c.bytes += rbuf->data_size;
}

std::map<std::string, ChannelCount> ChannelRateMonitor::Totals() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return totals_;
}

std::string ChannelRateMonitor::RateReport(double interval_s) {
  std::lock_guard<std::mutex> lock(mutex_);
  std::string out;
  char line[512];
  for (const auto& [channel, total] : totals_) {
    const ChannelCount& before = at_last_report_[channel];
    const double hz = interval_s > 0 ? (total.messages - before.messages) / interval_s : 0.0;
    const double kbps = interval_s > 0 ? (total.bytes - before.bytes) / interval_s / 1000.0 : 0.0;
    // A channel name from the network is hostile text: escaped (a valid one is unchanged).
    std::snprintf(line, sizeof line, "%-32s %9.1f Hz %9.1f kB/s  total %lld\n",
                  messages::EscapeForDisplay(channel, 63).c_str(),
                  hz, kbps, static_cast<long long>(total.messages));
    out += line;
  }
  at_last_report_ = totals_;
  if (out.empty()) out = "(no messages yet)\n";
  return out;
}

}  // namespace snapthread::viewer
