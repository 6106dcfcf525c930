// snapthread-web as the role tests' second observer: the bridge started on an observer
// credential (port chosen by the kernel), and a reader of its live WebSocket on loopback
// that counts what the bridge passed on to the page: shapes (and the scene they name),
// and any message carrying a forger's marker (kForgedMarker), which must stay 0.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "child_process.h"

namespace snapthread::roles_test {

class WebFeed {
 public:
  // Starts bin/snapthread-web --key `key` on `session` (logs in dir), waits for its URL
  // and opens the WebSocket; ok() tells whether all of that worked (error() why not).
  WebFeed(const std::string& bin, const std::string& key, const std::string& session, const std::string& dir);
  ~WebFeed();
  WebFeed(const WebFeed&) = delete;
  WebFeed& operator=(const WebFeed&) = delete;

  bool ok() const { return fd_ >= 0; }
  const std::string& error() const { return error_; }
  int64_t shapes() const { return shapes_.load(); }
  int64_t forged() const { return forged_.load(); }
  std::string last_scene();
  test_support::ChildProcess& process() { return *web_; }

 private:
  bool Open(int port);
  void Read();
  bool ReadExactly(void* out, size_t n);

  std::unique_ptr<test_support::ChildProcess> web_;
  int fd_ = -1;
  std::string error_;
  std::atomic<bool> stop_{false};
  std::atomic<int64_t> shapes_{0}, forged_{0};
  std::mutex mutex_;
  std::string last_scene_;
  std::thread thread_;
};

}  // namespace snapthread::roles_test
