#include "checkpoint_writer.h"

#include <pthread.h>
#include <sched.h>

#include <exception>
#include <utility>

#include <spdlog/spdlog.h>

namespace snapthread::server {
namespace {

using SteadyClock = std::chrono::steady_clock;
// A disk that keeps failing is reported once per this period, not at the checkpoint rate.
constexpr auto kErrorLogPeriod = std::chrono::seconds(10);

}  // namespace

CheckpointWriter::CheckpointWriter(std::string path, const auth::SessionKey& key,
                                   std::function<void()> before_write)
    : path_(std::move(path)), key_(key), before_write_(std::move(before_write)) {
  thread_ = std::thread([this] { Loop(); });
}

CheckpointWriter::~CheckpointWriter() {
  Flush();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  cv_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void CheckpointWriter::Offer(Checkpoint snapshot) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    pending_ = std::move(snapshot);
    ++offered_;
  }
  cv_.notify_one();
}

void CheckpointWriter::Flush() {
  std::unique_lock<std::mutex> lock(mutex_);
  done_cv_.wait(lock, [this] { return (!pending_ && !writing_) || stop_; });
}

CheckpointWriterStats CheckpointWriter::Stats() const {
  std::lock_guard<std::mutex> lock(mutex_);
  CheckpointWriterStats s;
  s.offered = offered_;
  s.written = written_;
  s.failed = failed_;
  const realtime::PercentileSummary w = write_us_.Compute();
  s.write_us_p50 = w.p50;
  s.write_us_p99 = w.p99;
  s.write_us_max = w.max;
  return s;
}

void CheckpointWriter::Loop() {
  // SCHED_BATCH (no privilege needed): the scheduler does not let this thread preempt the
  // solve thread when Offer wakes it; it writes when a core is free.
  const sched_param batch{};
  pthread_setschedparam(pthread_self(), SCHED_BATCH, &batch);
  std::unique_lock<std::mutex> lock(mutex_);
  while (true) {
    cv_.wait(lock, [this] { return pending_.has_value() || stop_; });
    if (!pending_) return;  // stop, nothing left to write
    Checkpoint snapshot = std::move(*pending_);
    pending_.reset();
    writing_ = true;
    lock.unlock();

    if (before_write_) before_write_();
    const auto t0 = SteadyClock::now();
    std::string error;
    try {
      const std::string bytes = EncodeCheckpoint(snapshot, key_);
      if (bytes.size() > kMaxCheckpointBytes) {
        error = "checkpoint " + path_ + " not written: " + std::to_string(bytes.size()) +
                " bytes is over the limit of " + std::to_string(kMaxCheckpointBytes);
      } else {
        WriteFileAtomically(path_, bytes);
      }
    } catch (const std::exception& e) {
      error = e.what();
    }
    const double us = std::chrono::duration<double, std::micro>(SteadyClock::now() - t0).count();

    lock.lock();
    writing_ = false;
    if (error.empty()) {
      ++written_;
      write_us_.Push(us);
    } else {
      ++failed_;
      const auto now = SteadyClock::now();
      if (failed_ == 1 || now - last_error_log_ >= kErrorLogPeriod) {
        last_error_log_ = now;
        spdlog::error("server: {} ({} checkpoint writes failed so far; serving continues)", error,
                      failed_);
      }
    }
    done_cv_.notify_all();
  }
}

}  // namespace snapthread::server
