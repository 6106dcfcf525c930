// The logger's queue between LCM's handler thread and the file writer, bounded in bytes:
// a message that would take the queue past its limit is dropped and counted, so a disk
// slower than the network (or a flood) costs messages, never the machine's memory.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <mutex>
#include <string>
#include <vector>

namespace snapthread::logger {

struct QueuedMessage {
  int64_t timestamp_us = 0;
  std::string channel;
  std::vector<uint8_t> data;
};

struct QueueCounts {
  int64_t dropped_messages = 0;  // refused because the queue was full
  int64_t dropped_bytes = 0;
  int64_t peak_bytes = 0;        // the most the queue held
};

class MessageQueue {
 public:
  // Bytes a message occupies in the queue: its channel and data plus the bookkeeping.
  static int64_t Footprint(size_t channel_size, size_t data_size) {
    return int64_t(channel_size + data_size + sizeof(QueuedMessage) + 32);
  }

  explicit MessageQueue(int64_t max_bytes) : max_bytes_(max_bytes) {}

  // Copies the message in; false (and counted) when it does not fit under the limit. One
  // producer (LCM's handler thread); it wakes the consumer only when that one waits.
  bool Push(int64_t timestamp_us, const std::string& channel, const void* data, size_t size);
  // Waits up to `timeout` for messages and takes all of them at once into *batch (one
  // wake-up per batch, not per message); false when none came (at once when closed and
  // empty). The batch still counts against the limit until Release(its bytes).
  bool TakeAll(std::deque<QueuedMessage>* batch, int64_t* batch_bytes,
               std::chrono::milliseconds timeout);
  void Release(int64_t batch_bytes);
  // No more pushes; TakeAll hands over what is left and then returns false at once.
  void Close();
  QueueCounts counts() const;
  int64_t max_bytes() const { return max_bytes_; }

 private:
  const int64_t max_bytes_;
  mutable std::mutex mutex_;
  std::condition_variable ready_;
  std::deque<QueuedMessage> queue_;
  int64_t bytes_ = 0;  // queued and taken but not yet released
  bool closed_ = false;
  bool consumer_waiting_ = false;
  QueueCounts counts_;
};

}  // namespace snapthread::logger
