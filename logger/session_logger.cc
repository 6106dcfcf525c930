#include "session_logger.h"

#include <poll.h>
#include <sys/stat.h>

#include <chrono>
#include <stdexcept>

#include "messages/lcm_url.h"
#include "messages/subscribe.h"

namespace snapthread::logger {
namespace {

using Clock = std::chrono::steady_clock;

// A FIFO would block the open for a reader, /dev/zero would swallow the log: only a new
// or a regular file is a log file. Throws for anything else; true when it exists.
bool ExistingRegularFile(const std::string& path) {
  struct stat st {};
  if (stat(path.c_str(), &st) != 0) return false;
  if (!S_ISREG(st.st_mode)) {
    throw std::runtime_error(path + " is " + (S_ISDIR(st.st_mode) ? "a directory" : "not a regular file") +
                             " (a FIFO or device): the log must be a file");
  }
  return true;
}

}  // namespace

SessionLogger::SessionLogger(const LoggerOptions& options) : options_(options), lcm_(options.lcm_url) {
  if (!lcm_.good()) {
    throw std::runtime_error("cannot open LCM at " + options_.lcm_url + ". " +
                             transport::LcmStartHint(options_.lcm_url));
  }
  if (ExistingRegularFile(options_.path) && !options_.force) {
    throw std::runtime_error("refusing to overwrite existing file " + options_.path +
                             " (--force overwrites it)");
  }
  log_ = std::make_unique<lcm::LogFile>(options_.path, "w");
  if (!log_->good()) throw std::runtime_error("cannot write the log file " + options_.path);
  subscription_ = messages::Subscribe<&SessionLogger::OnMessage>(lcm_, options_.channel, this);
  if (subscription_ == nullptr) {
    throw std::runtime_error("cannot subscribe to channels '" + options_.channel + "'");
  }
  subscription_->setQueueCapacity(kQueueMessages);
}

SessionLogger::~SessionLogger() {
  if (subscription_ != nullptr) lcm_.unsubscribe(subscription_);
}  // log_ flushes and closes the file

void SessionLogger::OnMessage(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
  lcm::LogEvent event;
  event.eventnum = 0;  // numbered by the log file
  event.timestamp = rbuf->recv_utime;
  event.channel = channel;
  event.datalen = static_cast<int32_t>(rbuf->data_size);
  event.data = rbuf->data;
  if (log_->writeEvent(&event) != 0) {
    write_errors_++;
    return;
  }
  messages_++;
  bytes_ += rbuf->data_size;
}

bool SessionLogger::Run(int stop_fd) {
  const auto start = Clock::now();
  auto last_flush = start;
  const auto flush_every = std::chrono::milliseconds(options_.flush_interval_ms);
  const int lcm_fd = lcm_.getFileno();
  while (true) {
    const auto now = Clock::now();
    if (options_.duration_s > 0 &&
        std::chrono::duration<double>(now - start).count() >= options_.duration_s) {
      break;
    }
    if (now - last_flush >= flush_every) {
      std::fflush(log_->getFilePtr());
      last_flush = now;
    }
    pollfd fds[2] = {{lcm_fd, POLLIN, 0}, {stop_fd, POLLIN, 0}};
    const int ready = poll(fds, stop_fd >= 0 ? 2 : 1, options_.flush_interval_ms);
    if (ready < 0) continue;  // EINTR
    if (stop_fd >= 0 && (fds[1].revents & POLLIN) != 0) break;
    if ((fds[0].revents & POLLIN) != 0 && lcm_.handle() != 0) return false;
  }
  std::fflush(log_->getFilePtr());
  return true;
}

}  // namespace snapthread::logger
