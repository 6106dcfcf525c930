#include "message_queue.h"

#include <algorithm>
#include <cstring>

namespace snapthread::logger {

bool MessageQueue::Push(int64_t timestamp_us, const std::string& channel, const void* data,
                        size_t size) {
  const int64_t footprint = Footprint(channel.size(), size);
  bool wake = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (closed_ || bytes_ + footprint > max_bytes_) {
      counts_.dropped_messages++;
      counts_.dropped_bytes += int64_t(size);
      return false;
    }
    bytes_ += footprint;  // reserved before the copy, so the limit holds meanwhile
    counts_.peak_bytes = std::max(counts_.peak_bytes, bytes_);
  }
  QueuedMessage m;
  m.timestamp_us = timestamp_us;
  m.channel = channel;
  m.data.resize(size);
  if (size > 0) std::memcpy(m.data.data(), data, size);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    queue_.push_back(std::move(m));
    wake = consumer_waiting_;
  }
  if (wake) ready_.notify_one();
  return true;
}

bool MessageQueue::TakeAll(std::deque<QueuedMessage>* batch, int64_t* batch_bytes,
                           std::chrono::milliseconds timeout) {
  batch->clear();
  *batch_bytes = 0;
  std::unique_lock<std::mutex> lock(mutex_);
  if (queue_.empty() && !closed_) {
    consumer_waiting_ = true;
    ready_.wait_for(lock, timeout, [&] { return !queue_.empty() || closed_; });
    consumer_waiting_ = false;
  }
  if (queue_.empty()) return false;
  batch->swap(queue_);
  for (const QueuedMessage& m : *batch) *batch_bytes += Footprint(m.channel.size(), m.data.size());
  return true;
}

void MessageQueue::Release(int64_t batch_bytes) {
  std::lock_guard<std::mutex> lock(mutex_);
  bytes_ -= batch_bytes;
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
