#include "web_feed.h"

#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <vector>

#include "environment.h"
#include "loopback_socket.h"
#include "session_watch.h"

namespace snapthread::roles_test {

WebFeed::WebFeed(const std::string& bin, const std::string& key, const std::string& session, const std::string& dir) {
  web_ = std::make_unique<test_support::ChildProcess>(
      std::vector<std::string>{bin + "/snapthread-web", "--key", key, "--session", session, "--lcm-url",
                               test_support::kLoopbackLcmUrl, "--port", "0", "--duration-s", "120"},
      test_support::OutputFiles(dir + "/web.out", dir + "/web.err"));
  const std::string marker = "at http://127.0.0.1:";
  if (!web_->started() || !web_->WaitForOutput(marker, 30)) {
    error_ = "snapthread-web did not serve: " + web_->Out() + web_->Err();
    return;
  }
  const std::string out = web_->Out();
  const int port = std::atoi(out.c_str() + out.find(marker) + marker.size());
  if (Open(port)) thread_ = std::thread([this] { Read(); });
}

WebFeed::~WebFeed() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
  if (fd_ >= 0) ::close(fd_);
}

std::string WebFeed::last_scene() {
  std::lock_guard<std::mutex> lock(mutex_);
  return last_scene_;
}

// The WebSocket handshake as the page makes it (its own Host and Origin).
bool WebFeed::Open(int port) {
  const int fd = test_support::ConnectLoopback(port, 1);
  if (fd < 0) {
    error_ = "no connection to port " + std::to_string(port);
    return false;
  }
  const std::string host = "127.0.0.1:" + std::to_string(port);
  const std::string request = "GET /ws HTTP/1.1\r\nHost: " + host + "\r\nOrigin: http://" + host +
                              "\r\nConnection: Upgrade\r\nUpgrade: websocket\r\nSec-WebSocket-Version: 13\r\n"
                              "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n\r\n";
  if (::send(fd, request.data(), request.size(), MSG_NOSIGNAL) != static_cast<ssize_t>(request.size())) {
    ::close(fd);
    error_ = "handshake not sent";
    return false;
  }
  std::string head;
  char c = 0;
  for (int tries = 0; head.find("\r\n\r\n") == std::string::npos && head.size() < 8192;) {
    const ssize_t n = ::recv(fd, &c, 1, 0);
    if (n == 1) {
      head += c;
    } else if (++tries > 30) {
      break;
    }
  }
  if (head.find(" 101 ") == std::string::npos) {
    ::close(fd);
    error_ = "handshake refused: " + head;
    return false;
  }
  fd_ = fd;
  return true;
}

// n bytes, waiting through the socket's 1 s timeouts until Stop.
bool WebFeed::ReadExactly(void* out, size_t n) {
  auto* p = static_cast<uint8_t*>(out);
  while (n > 0) {
    const ssize_t got = ::recv(fd_, p, n, 0);
    if (got > 0) {
      p += got;
      n -= static_cast<size_t>(got);
    } else if (got < 0 && (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR) && !stop_) {
      continue;
    } else {
      return false;
    }
  }
  return true;
}

// Server frames (unmasked): text frames counted, shapes and force models acknowledged as
// the page does; a close frame ends the reading.
void WebFeed::Read() {
  std::vector<uint8_t> payload;
  while (!stop_) {
    uint8_t header[2];
    if (!ReadExactly(header, 2)) return;
    uint64_t length = header[1] & 0x7f;
    if (length == 126 || length == 127) {
      uint8_t ext[8];
      const size_t bytes = length == 126 ? 2 : 8;
      if (!ReadExactly(ext, bytes)) return;
      length = 0;
      for (size_t i = 0; i < bytes; ++i) length = (length << 8) | ext[i];
    }
    if (length > (64u << 20)) return;
    payload.resize(length);
    if (length > 0 && !ReadExactly(payload.data(), length)) return;
    const int opcode = header[0] & 0x0f;
    if (opcode == 8) return;
    if (opcode != 1) continue;
    const std::string text(payload.begin(), payload.end());
    if (text.rfind("{\"type\":\"shape\"", 0) == 0 || text.rfind("{\"type\":\"force\"", 0) == 0) {
      // The page acknowledges each paced message (web/client_pacer.h): a masked "ack".
      static const uint8_t kAck[] = {0x81, 0x83, 1, 2, 3, 4, 'a' ^ 1, 'c' ^ 2, 'k' ^ 3};
      if (::send(fd_, kAck, sizeof kAck, MSG_NOSIGNAL) != static_cast<ssize_t>(sizeof kAck)) return;
    }
    if (text.find(kForgedMarker) != std::string::npos) forged_++;
    if (text.rfind("{\"type\":\"shape\"", 0) == 0) {
      shapes_++;
      const std::string key = "\"scene\":\"";
      const size_t at = text.find(key);
      if (at != std::string::npos) {
        const size_t end = text.find('"', at + key.size());
        std::lock_guard<std::mutex> lock(mutex_);
        last_scene_ = text.substr(at + key.size(), end - at - key.size());
      }
    }
  }
}

}  // namespace snapthread::roles_test
