// An lcm::LCM handled on a thread of its own: the receiving side of a process test, whose
// handlers run on that thread while the test waits on what they record. Header-only: for
// the test binaries that link LCM (the service, attack and web tests).
#pragma once

#include <atomic>
#include <string>
#include <thread>

#include <lcm/lcm-cpp.hpp>

namespace snapthread::test_support {

class LcmThread {
 public:
  explicit LcmThread(const std::string& url) : lcm_(url) {}
  ~LcmThread() { Stop(); }
  LcmThread(const LcmThread&) = delete;
  LcmThread& operator=(const LcmThread&) = delete;

  // Subscribe (messages::Subscribe) here before Start(); publishing from any thread.
  lcm::LCM& lcm() { return lcm_; }
  // Handles what arrives (20 ms waits, so Stop() takes at most that long) until Stop().
  void Start() {
    thread_ = std::thread([this] {
      while (!stop_) lcm_.handleTimeout(20);
    });
  }
  // No handler runs once this returns. A listener whose handlers use its own members calls
  // it first in its destructor, before those members go.
  void Stop() {
    stop_ = true;
    if (thread_.joinable()) thread_.join();
  }

 private:
  lcm::LCM lcm_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace snapthread::test_support
