// The attack suite, snapthread-web under a forged-id flood: a sender holding no key
// publishes device statuses under 100 invented device ids (and forged shapes and solver
// statuses) on a genuine session's channels, starting before the genuine device does.
// The bridge keeps per-device state (a sequence floor) for at most 16 devices; before this
// suite it made that state before checking the MAC, so the first 16 forged ids took every
// place and the genuine device's statuses were refused for good. Asserted here, against
// the real binaries (server, sim-path device, snapthread-web) over udpm on loopback: the
// page's WebSocket carries the genuine device's statuses and the genuine shapes only,
// the forged ones are refused (counted), and shapes keep flowing during the flood.
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstring>
#include <random>
#include <regex>
#include <set>
#include <string>
#include <thread>

#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include "messages/channels.h"
#include "sample_messages.h"
#include "loopback_socket.h"
#include "test_support.h"

namespace snapthread::attack_test {
namespace {

using test_support::ChildProcess;
using test_support::OneLog;

constexpr int kForgedIds = 100;

// A keyless sender: every 50 ms a device status under each of the 100 forged ids, a shape
// and a solver status, all with invented epochs, sequence numbers and MACs.
class Flooder {
 public:
  Flooder(const std::string& session) : channels_(session) {}
  ~Flooder() { Stop(); }
  void Start() {
    thread_ = std::thread([this] { Run(); });
  }
  void Stop() {
    running_ = false;
    if (thread_.joinable()) thread_.join();
  }
  int64_t sent() const { return sent_; }

 private:
  void Run() {
    lcm::LCM lcm(test_support::kLoopbackLcmUrl);
    std::mt19937_64 rng(23);
    auto forge = [&](auto* m) {
      m->epoch = static_cast<int64_t>(rng());
      m->auth_seq = static_cast<int64_t>(rng() >> 1);
      for (auto& b : m->mac) b = static_cast<uint8_t>(rng());
    };
    int64_t round = 0;
    while (running_) {
      for (int i = 0; i < kForgedIds; ++i) {
        device_status_t d = test_support::Sample<device_status_t>();
        d.device_id = "forged-" + std::to_string(i);
        d.seq = round;
        forge(&d);
        lcm.publish(channels_.device_status, &d);
      }
      thread_shape_t s = test_support::SampleShape(5);
      s.scene = "FORGED";
      s.seq = round;
      forge(&s);
      lcm.publish(channels_.shape, &s);
      solver_status_t st = test_support::Sample<solver_status_t>();
      st.scene = "FORGED";
      forge(&st);
      lcm.publish(channels_.solver_status, &st);
      sent_ += kForgedIds + 2;
      ++round;
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
  }

  messages::Channels channels_;
  std::thread thread_;
  std::atomic<bool> running_{true};
  std::atomic<int64_t> sent_{0};
};

// A minimal WebSocket client over a blocking socket (the bridge's frames are unmasked
// text; the client's must be masked: a zero mask leaves the payload as is).
class WsReader {
 public:
  bool Open(int port) {
    fd_ = test_support::ConnectLoopback(port, 5);
    if (fd_ < 0) return false;
    const std::string host = "127.0.0.1:" + std::to_string(port);
    const std::string request = "GET /ws HTTP/1.1\r\nHost: " + host + "\r\nOrigin: http://" + host +
                                "\r\nConnection: Upgrade\r\nUpgrade: websocket\r\nSec-WebSocket-Version: 13\r\n"
                                "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n\r\n";
    ::send(fd_, request.data(), request.size(), MSG_NOSIGNAL);
    std::string head;
    char c;
    while (head.find("\r\n\r\n") == std::string::npos && ::recv(fd_, &c, 1, 0) == 1) head += c;
    return head.rfind("HTTP/1.1 101", 0) == 0;
  }
  ~WsReader() {
    if (fd_ >= 0) ::close(fd_);
  }
  // The next text message ("" on a timeout or a closed connection).
  std::string Next() {
    uint8_t h[2];
    if (!Read(h, 2)) return "";
    uint64_t n = h[1] & 0x7f;
    if (n == 126 || n == 127) {
      uint8_t ext[8];
      const int k = n == 126 ? 2 : 8;
      if (!Read(ext, k)) return "";
      n = 0;
      for (int i = 0; i < k; ++i) n = (n << 8) | ext[i];
    }
    std::string payload(n, '\0');
    if (n > 0 && !Read(payload.data(), n)) return "";
    if ((h[0] & 0x0f) == 0x9) Send(0xA, payload);  // ping: pong
    return payload;
  }
  void Send(uint8_t opcode, const std::string& text) {
    std::string frame;
    frame += static_cast<char>(0x80 | opcode);
    frame += static_cast<char>(0x80 | text.size());  // short control and "ack" messages
    frame.append(4, '\0');
    frame += text;
    ::send(fd_, frame.data(), frame.size(), MSG_NOSIGNAL);
  }

 private:
  bool Read(void* out, size_t n) {
    auto* p = static_cast<char*>(out);
    while (n > 0) {
      const ssize_t got = ::recv(fd_, p, n, 0);
      if (got <= 0) return false;
      p += got;
      n -= static_cast<size_t>(got);
    }
    return true;
  }
  int fd_ = -1;
};

std::string StringField(const std::string& json, const std::string& key) {
  std::smatch m;
  if (std::regex_search(json, m, std::regex("\"" + key + "\":\"([^\"]*)\""))) return m[1];
  return "";
}

TEST(WebFlood, AHundredForgedDeviceIdsDoNotPushOutTheGenuineDevice) {
  test_support::SessionKeyFile key;
  test_support::ScopedTempDir dir("web-flood");
  const std::string bin = test_support::BinDir();
  const std::string session = test_support::UniqueSession("WEBFLOOD");
  const std::string scene = test_support::ScenePath("curve2d_snap.yaml");
  const std::string url = test_support::kLoopbackLcmUrl;

  ChildProcess web({bin + "/snapthread-web", "--port", "0", "--session", session, "--lcm-url", url},
                   OneLog(dir.path() + "/web.txt", true));
  ASSERT_TRUE(web.WaitForOutput(" at http://", 30)) << web.Out();
  std::smatch m;
  const std::string out = web.Out();
  ASSERT_TRUE(std::regex_search(out, m, std::regex(R"(at http://[^:]+:(\d+)/)"))) << out;
  const int port = std::stoi(m[1]);

  // The flood first: the forged ids reach the bridge before any genuine device status.
  Flooder flood(session);
  flood.Start();
  std::this_thread::sleep_for(std::chrono::seconds(1));
  ChildProcess server({bin + "/snapthread-server", "--scene", scene, "--session", session, "--lcm-url", url,
                       "--duration", "60"},
                      OneLog(dir.path() + "/server.txt", true));
  ASSERT_TRUE(server.WaitForOutput("server: session", 60)) << server.Out();
  ChildProcess device({bin + "/snapthread-device", "--backend", "sim-path", "--scene", scene, "--session",
                       session, "--lcm-url", url, "--duration", "40", "--no-rt"},
                      OneLog(dir.path() + "/device.txt", true));

  WsReader ws;
  ASSERT_TRUE(ws.Open(port));
  std::set<std::string> device_ids, shape_scenes, solver_scenes;
  int devices = 0, shapes = 0;
  std::string bridge;
  const auto start = std::chrono::steady_clock::now();
  // Until 5 genuine device statuses (2 Hz) and 50 shapes came, or 60 s.
  while ((devices < 5 || shapes < 50) && std::chrono::steady_clock::now() - start < std::chrono::seconds(60)) {
    const std::string msg = ws.Next();
    if (msg.empty()) continue;
    const std::string type = StringField(msg, "type");
    if (type == "shape" || type == "force") ws.Send(0x1, "ack");
    if (type == "device") devices++, device_ids.insert(StringField(msg, "device_id"));
    if (type == "shape") shapes++, shape_scenes.insert(StringField(msg, "scene"));
    if (type == "solver") solver_scenes.insert(StringField(msg, "scene"));
    if (type == "bridge") bridge = msg;
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  flood.Stop();
  std::printf("web_flood_test: %d genuine device statuses and %d shapes in %.1f s during a flood of %lld "
              "forged messages; bridge: %s\n",
              devices, shapes, seconds, static_cast<long long>(flood.sent()), bridge.c_str());
  EXPECT_GE(devices, 5) << "the genuine device's statuses stopped reaching the page";
  EXPECT_GE(shapes, 50);
  ASSERT_FALSE(device_ids.empty());
  for (const std::string& id : device_ids) EXPECT_EQ(id.rfind("sim-path", 0), 0u) << "a forged id was forwarded: " << id;
  EXPECT_EQ(shape_scenes, std::set<std::string>{"curve2d_snap"});
  EXPECT_EQ(solver_scenes.count("FORGED"), 0u);
  std::smatch rejected;
  ASSERT_TRUE(std::regex_search(bridge, rejected, std::regex(R"("auth_rejected":(\d+))"))) << bridge;
  EXPECT_GT(std::stoll(rejected[1]), 1000) << "the forged messages are refused and counted";

  EXPECT_TRUE(test_support::TerminateTogether({&device, &server}, 10)) << "device or server killed";
  web.Signal(SIGTERM);
  EXPECT_TRUE(web.WaitOrKill(10));
}

}  // namespace
}  // namespace snapthread::attack_test
