#include "session_logger.h"

#include <poll.h>

#include <chrono>
#include <cstdio>
#include <stdexcept>
#include <thread>

#include "messages/lcm_url.h"
#include "messages/subscribe.h"

namespace snapthread::logger {
namespace {

using Clock = std::chrono::steady_clock;

LogFileOptions FileOptions(const LoggerOptions& o) {
  LogFileOptions f;
  f.path = o.path;
  f.force = o.force;
  f.max_bytes = o.max_bytes;
  f.rotate = o.rotate;
  return f;
}

}  // namespace

SessionLogger::SessionLogger(const LoggerOptions& options)
    : options_(options), lcm_(options.lcm_url), queue_(options.max_queue_bytes) {
  if (options_.max_queue_bytes <= 0) throw std::runtime_error("--max-queue-bytes must be positive");
  if (!lcm_.good()) {
    throw std::runtime_error("cannot open LCM at " + options_.lcm_url + ". " +
                             messages::LcmStartHint(options_.lcm_url));
  }
  writer_ = std::make_unique<LogFileWriter>(FileOptions(options_));
  subscription_ = messages::Subscribe<&SessionLogger::OnMessage>(lcm_, options_.channel, this);
  if (subscription_ == nullptr) {
    throw std::runtime_error("cannot subscribe to channels '" + options_.channel + "'");
  }
  subscription_->setQueueCapacity(kLcmQueueMessages);
}

SessionLogger::~SessionLogger() {
  if (subscription_ != nullptr) lcm_.unsubscribe(subscription_);
}  // writer_ flushes and closes the file

void SessionLogger::OnMessage(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
  queue_.Push(rbuf->recv_utime, channel, rbuf->data, rbuf->data_size);  // a drop is counted
}

void SessionLogger::WriteLoop() {
  const auto flush_every = std::chrono::milliseconds(options_.flush_interval_ms);
  auto last_flush = Clock::now();
  const auto write = [&](const QueuedMessage& m) {
    if (writer_failed_) {
      write_errors_++;
      return;
    }
    switch (writer_->Write(m.timestamp_us, m.channel, m.data.data(), int32_t(m.data.size()))) {
      case LogFileWriter::Result::kWritten:
        messages_++;
        bytes_ += int64_t(m.data.size());
        break;
      case LogFileWriter::Result::kTooLarge:
        too_large_++;
        break;
      case LogFileWriter::Result::kFailed:
        write_errors_++;
        writer_failed_ = true;
        break;
    }
  };
  std::deque<QueuedMessage> batch;
  int64_t batch_bytes = 0;
  const auto write_batch = [&] {
    for (const QueuedMessage& m : batch) write(m);
    queue_.Release(batch_bytes);
  };
  while (!stop_writer_) {
    if (queue_.TakeAll(&batch, &batch_bytes, flush_every)) write_batch();
    if (Clock::now() - last_flush >= flush_every) {
      writer_->Flush();
      last_flush = Clock::now();
    }
  }
  // The LCM loop has ended and the queue is closed: write out what it still holds.
  while (queue_.TakeAll(&batch, &batch_bytes, std::chrono::milliseconds(0))) write_batch();
  writer_->Flush();
}

bool SessionLogger::Run(int stop_fd) {
  std::thread writer([this] { WriteLoop(); });
  const auto start = Clock::now();
  auto last_report = start;
  int64_t reported_drops = 0;
  const int lcm_fd = lcm_.getFileno();
  bool ok = true;
  while (true) {
    const auto now = Clock::now();
    if (options_.duration_s > 0 &&
        std::chrono::duration<double>(now - start).count() >= options_.duration_s) {
      break;
    }
    if (writer_failed_) {
      ok = false;
      break;
    }
    if (now - last_report >= std::chrono::seconds(1)) {
      // At most one line a second about a full queue (a disk slower than the network).
      const QueueCounts c = queue_.counts();
      if (c.dropped_messages > reported_drops) {
        std::fprintf(stderr,
                     "snapthread-logger: queue full (%lld bytes unwritten at most): dropped %lld "
                     "messages in the last %.1f s; %lld (%lld bytes) since start\n",
                     static_cast<long long>(queue_.max_bytes()),
                     static_cast<long long>(c.dropped_messages - reported_drops),
                     std::chrono::duration<double>(now - last_report).count(),
                     static_cast<long long>(c.dropped_messages),
                     static_cast<long long>(c.dropped_bytes));
        reported_drops = c.dropped_messages;
      }
      last_report = now;
    }
    pollfd fds[2] = {{lcm_fd, POLLIN, 0}, {stop_fd, POLLIN, 0}};
    const int ready = poll(fds, stop_fd >= 0 ? 2 : 1, options_.flush_interval_ms);
    if (ready < 0) continue;  // EINTR
    if (stop_fd >= 0 && (fds[1].revents & POLLIN) != 0) break;
    if ((fds[0].revents & POLLIN) != 0 && lcm_.handle() != 0) {
      ok = false;
      break;
    }
  }
  queue_.Close();
  stop_writer_ = true;
  writer.join();
  return ok && !writer_failed_;
}

}  // namespace snapthread::logger
