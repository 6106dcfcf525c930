#include "message_queue.h"

#include <algorithm>
#include <cstring>

namespace snapthread::logger {

bool MessageQueue::Push(int64_t timestamp_us, const std::string& channel, const void* data,
                        size_t size) {
  const int64_t footprint = Footprint(channel.size(), size);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (closed_ || bytes_ + footprint > max_bytes_) {
      counts_.dropped_messages++;
      counts_.dropped_bytes += int64_t(size);
      return false;
    }
    bytes_ += footprint;
    counts_.peak_bytes = std::max(counts_.peak_bytes, bytes_);
  }
  // Copied outside the lock; the space is already reserved.
  QueuedMessage m;
  m.timestamp_us = timestamp_us;
  m.channel = channel;
  m.data.resize(size);
  if (size > 0) std::memcpy(m.data.data(), data, size);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    queue_.push_back(std::move(m));
  }
  ready_.notify_one();
  return true;
}

bool MessageQueue::Pop(QueuedMessage* out, std::chrono::milliseconds timeout) {
  std::unique_lock<std::mutex> lock(mutex_);
  if (!ready_.wait_for(lock, timeout, [&] { return !queue_.empty() || closed_; })) return false;
  if (queue_.empty()) return false;
  *out = std::move(queue_.front());
  queue_.pop_front();
  bytes_ -= Footprint(out->channel.size(), out->data.size());
  return true;
}

void MessageQueue::Close() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    closed_ = true;
  }
  ready_.notify_all();
}

QueueCounts MessageQueue::counts() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return counts_;
}

}  // namespace snapthread::logger
