// Writes the server's checkpoints off the solve thread. The solve
// thread hands over a snapshot (a copy of the grasp and the state, the scene and the
// method) with Offer, which only swaps it into a slot under a mutex that is never held
// during I/O; the writer thread encodes, signs and writes the newest snapshot with
// WriteFileAtomically (temp file, fsync, rename, fsync of the directory). A slow disk
// makes the writer skip to the newest snapshot; it never makes the solve loop wait.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "auth/session_key.h"
#include "checkpoint.h"
#include "realtime/percentiles.h"

namespace snapthread::server {

struct CheckpointWriterStats {
  int64_t offered = 0;  // snapshots handed over by the solve thread
  int64_t written = 0;  // files committed (rename + directory fsync done)
  int64_t failed = 0;   // writes that failed (logged, rate-limited)
  // Encode + sign + write + fsync + rename + directory fsync, per committed file (last
  // kWindow writes), µs.
  double write_us_p50 = 0.0, write_us_p99 = 0.0, write_us_max = 0.0;
};

class CheckpointWriter {
 public:
  static constexpr size_t kWindow = 4096;

  // `key` signs the files and must outlive the writer. Starts the writer thread.
  // `before_write` (tests) runs on the writer thread before each write: a test blocks
  // there to stand for a slow disk.
  CheckpointWriter(std::string path, const auth::SessionKey& key,
                   std::function<void()> before_write = {});
  // Flush() then stops the thread.
  ~CheckpointWriter();
  CheckpointWriter(const CheckpointWriter&) = delete;
  CheckpointWriter& operator=(const CheckpointWriter&) = delete;

  // Any thread (the solve thread): the newest snapshot, replacing one not yet written.
  void Offer(Checkpoint snapshot);
  // Waits until everything offered so far is written (or failed). For a clean stop.
  void Flush();

  const std::string& path() const { return path_; }
  CheckpointWriterStats Stats() const;

 private:
  void Loop();

  std::string path_;
  const auth::SessionKey& key_;
  std::function<void()> before_write_;
  mutable std::mutex mutex_;
  std::condition_variable cv_;       // a snapshot was offered, or stop
  std::condition_variable done_cv_;  // a write finished
  std::optional<Checkpoint> pending_;
  bool writing_ = false;
  bool stop_ = false;
  int64_t offered_ = 0, written_ = 0, failed_ = 0;
  realtime::SampleWindow write_us_{kWindow};
  std::chrono::steady_clock::time_point last_error_log_{};
  std::thread thread_;
};

}  // namespace snapthread::server
