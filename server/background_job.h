// One piece of work (a scene load) on its own thread with a time limit, polled by the
// solve thread so it never waits for it (the current scene keeps being
// served while a new one loads). A job past its limit is abandoned: reported once as
// timed out, its result discarded when it ends; a thread cannot be killed, so the job
// stays busy() until then and the destructor joins it.
#pragma once

#include <chrono>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

namespace snapthread::server {

template <typename T>
class BackgroundJob {
 public:
  using Clock = std::chrono::steady_clock;
  enum class State { kIdle, kRunning, kDone, kFailed, kTimedOut };
  // What a failed job threw: its message, and the exception itself (to tell its class).
  struct Failure {
    std::string message;
    std::exception_ptr error;
  };

  BackgroundJob() = default;
  ~BackgroundJob() { Join(); }
  BackgroundJob(const BackgroundJob&) = delete;
  BackgroundJob& operator=(const BackgroundJob&) = delete;

  // A job runs, or an abandoned one has not ended yet.
  bool busy() const { return thread_.joinable(); }

  // False when busy(). `work` runs on a new thread; what it throws is the failure.
  bool Start(std::function<std::unique_ptr<T>()> work, Clock::duration limit) {
    if (busy()) return false;
    deadline_ = Clock::now() + limit;
    abandoned_ = false;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      finished_ = false;
      result_.reset();
      failure_ = {};
    }
    thread_ = std::thread([this, work = std::move(work)] {
      std::unique_ptr<T> result;
      Failure failure;
      try {
        result = work();
      } catch (const std::exception& e) {
        failure = {e.what(), std::current_exception()};
      } catch (...) {
        failure = {"unknown error", std::current_exception()};
      }
      std::lock_guard<std::mutex> lock(mutex_);
      result_ = std::move(result);
      failure_ = std::move(failure);
      finished_ = true;
    });
    return true;
  }

  // Never blocks for the work. kDone: *out holds the result; kFailed: *failure says why;
  // kTimedOut: once, when the limit passes; kRunning; kIdle (nothing to report).
  State Poll(std::unique_ptr<T>* out, Failure* failure) {
    if (!busy()) return State::kIdle;
    bool finished = false;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      finished = finished_;
    }
    if (!finished) {
      if (abandoned_ || Clock::now() < deadline_) return State::kRunning;
      abandoned_ = true;
      return State::kTimedOut;
    }
    thread_.join();  // the work has returned: only the thread's exit remains
    std::lock_guard<std::mutex> lock(mutex_);
    if (abandoned_) return State::kIdle;  // already reported; the result is dropped
    if (result_ != nullptr) {
      *out = std::move(result_);
      return State::kDone;
    }
    *failure = std::move(failure_);
    return State::kFailed;
  }

  void Join() {
    if (thread_.joinable()) thread_.join();
  }

 private:
  std::thread thread_;
  Clock::time_point deadline_{};
  bool abandoned_ = false;  // owner thread only
  std::mutex mutex_;        // guards the fields below
  bool finished_ = false;
  std::unique_ptr<T> result_;
  Failure failure_;
};

}  // namespace snapthread::server
