// No datagram crashes a receiving binary (docs/security.md, "Malformed datagrams"): a live
// session over udpm on loopback (server, device, viewer on its own Xvfb, web bridge,
// logger) takes, mid-session, snapthread-fragment-sender's raw datagrams: the two-fragment
// crash of Debian's liblcm 1.3.1 on every channel of the session, offsets and sizes that
// overflow 32 bits, fragment counts 0 and huge, declared sizes over LCM's maximum,
// truncated headers, unterminated channel names. Every binary must still run afterwards,
// keep serving the session (models, statuses and shapes recorded after the attack, the
// device's own count of models rising, the viewer's screenshot taken after it, the web
// bridge answering), and its liblcm must have counted every malformed datagram on stderr.
//
// The session uses its own multicast group and port, so that the datagrams reach no other
// test's processes. With Debian's liblcm (a build with -DSNAPTHREAD_SYSTEM_LCM=ON) every
// receiving binary dies of SIGSEGV here.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/time.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <map>
#include <regex>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include "messages/channels.h"
#include "snapthread/device_status_t.hpp"
#include "test_support.h"

namespace snapthread {
namespace {

using namespace test_support;

// A group and port of this test alone (the other tests use 239.255.76.67:7667).
constexpr char kAttackUrl[] = "udpm://239.255.76.91:7691?ttl=0";

int64_t WallMicros() {
  timeval tv{};
  gettimeofday(&tv, nullptr);
  return static_cast<int64_t>(tv.tv_sec) * 1000000 + tv.tv_usec;
}

// The largest "N since start" of liblcm's lines about dropped datagrams in `text`
// (one count per receiving lcm_t; -1 when there is no such line).
long DroppedSinceStart(const std::string& text) {
  static const std::regex kLine(R"(LCM udpm: \d+ malformed datagrams dropped [^\n]*; (\d+) since start)");
  long most = -1;
  for (std::sregex_iterator it(text.begin(), text.end(), kLine), end; it != end; ++it) {
    most = std::max(most, std::stol((*it)[1]));
  }
  return most;
}

// How a child ended, for messages: "running", "exit 0", "SIGSEGV".
std::string State(ChildProcess& p) {
  if (p.running()) return "running";
  int code = -1;
  p.Wait(0.0, &code);
  if (code > 128) return std::string("killed by ") + strsignal(code - 128);
  return "exit " + std::to_string(code);
}

// An HTTP GET / on 127.0.0.1:port; the status line ("" when nothing answered).
std::string HttpStatusLine(int port) {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  if (fd < 0) return "";
  timeval tv{5, 0};
  setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof(tv));
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<uint16_t>(port));
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  std::string reply;
  if (connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof(a)) == 0) {
    const std::string req = "GET / HTTP/1.1\r\nHost: 127.0.0.1:" + std::to_string(port) +
                            "\r\nConnection: close\r\n\r\n";
    if (send(fd, req.data(), req.size(), 0) == static_cast<ssize_t>(req.size())) {
      char buf[512];
      const ssize_t n = recv(fd, buf, sizeof(buf), 0);
      if (n > 0) reply.assign(buf, static_cast<size_t>(n));
    }
  }
  close(fd);
  return reply.substr(0, reply.find("\r\n"));
}

// What the logger recorded after `after_us` (wall clock, as LCM stamps log events).
struct Recorded {
  std::map<std::string, long> events_after;  // per channel
  int64_t models_before = -1;                // device_status_t.models_received, last before
  int64_t models_after = -1;                 // and last after
};

Recorded ReadLog(const std::string& path, const messages::Channels& ch, int64_t after_us) {
  Recorded r;
  lcm::LogFile log(path, "r");
  if (!log.good()) return r;
  while (const lcm::LogEvent* e = log.readNextEvent()) {
    const bool after = e->timestamp > after_us;
    if (after) ++r.events_after[e->channel];
    if (e->channel != ch.device_status) continue;
    device_status_t st;
    if (st.decode(e->data, 0, static_cast<int>(e->datalen)) < 0) continue;
    (after ? r.models_after : r.models_before) = st.models_received;
  }
  return r;
}

TEST(LcmFragmentsTest, EveryReceivingBinarySurvivesAndCountsMalformedDatagrams) {
  const SessionKeyFile key_file;  // SNAPTHREAD_KEY_FILE for every binary
  const ScopedTempDir tmp("lcm-fragments");
  const std::string dir = tmp.path();
  const std::string bin = BinDir();
  const std::string session = UniqueSession("FRAG");
  const messages::Channels channels(session);
  const std::string scene = ScenePath("curve2d_snap.yaml");
  const std::string log = dir + "/session.lcmlog";
  const std::string shot = dir + "/viewer.png";
  const VirtualDisplay display(dir);
  ASSERT_TRUE(display.ready()) << display.error();

  ChildProcess logger({bin + "/snapthread-logger", "-c", session + "_.*", "--lcm-url", kAttackUrl, log},
                      OneLog(dir + "/logger.txt", true));
  ChildProcess server({bin + "/snapthread-server", "--scene", scene, "--session", session, "--lcm-url",
                       kAttackUrl, "--duration", "120", "--summary", dir + "/server.json", "--log-level",
                       "warn"},
                      OneLog(dir + "/server.txt", true));
  ChildProcess web({bin + "/snapthread-web", "--port", "0", "--session", session, "--lcm-url", kAttackUrl,
                    "--duration-s", "120"},
                   OneLog(dir + "/web.txt", true));
  ASSERT_TRUE(logger.started() && server.started() && web.started());
  ASSERT_TRUE(web.WaitForOutput(" at http://", 30)) << web.Out();
  std::smatch m;
  const std::string web_out = web.Out();
  ASSERT_TRUE(std::regex_search(web_out, m, std::regex(R"(at http://[^:/\s]+:(\d+))"))) << web_out;
  const int web_port = std::stoi(m[1]);
  // The viewer shoots after 400 shapes: at the server's 60 shapes/s, well after the attack
  // (which ends about 4 s after the viewer starts), so the picture is drawn from shapes
  // received after it.
  ChildProcess viewer(display.On({bin + "/snapthread-viewer", "--session", session, "--lcm-url", kAttackUrl,
                                  "--screenshot", shot, "--after-shapes", "400", "--timeout-s", "90"}),
                      OutputFiles(dir + "/viewer.txt", dir + "/viewer_err.txt", true));
  std::this_thread::sleep_for(std::chrono::milliseconds(800));
  ChildProcess device({bin + "/snapthread-device", "--backend", "virtual-hand", "--scene", scene, "--session",
                       session, "--lcm-url", kAttackUrl, "--duration", "12", "--no-rt", "--summary",
                       dir + "/device.json", "--log-level", "warn"},
                      OneLog(dir + "/device.txt", true));
  ASSERT_TRUE(viewer.started() && device.started());
  std::this_thread::sleep_for(std::chrono::milliseconds(2500));

  struct Binary {
    const char* name;
    ChildProcess* process;
  };
  std::vector<Binary> binaries = {{"snapthread-server", &server}, {"snapthread-device", &device},
                                  {"snapthread-viewer", &viewer}, {"snapthread-web", &web},
                                  {"snapthread-logger", &logger}};
  for (Binary& b : binaries) ASSERT_TRUE(b.process->running()) << b.name << " before the attack: " << State(*b.process);

  // The attack: 3 rounds, 200 ms apart.
  ChildProcess attack({bin + "/snapthread-fragment-sender", kAttackUrl, session, "3", "200"},
                      OneLog(dir + "/attack.txt", true));
  int code = -1;
  ASSERT_TRUE(attack.Wait(30.0, &code));
  ASSERT_EQ(code, 0) << attack.Out();
  const int64_t attack_end_us = WallMicros();
  const std::string attack_out = attack.Out();
  ASSERT_TRUE(std::regex_search(attack_out, m, std::regex(R"(sent (\d+) malformed)"))) << attack_out;
  const long sent = std::stol(m[1]);
  ASSERT_GT(sent, 100);

  // Every binary survives (give a dying one a moment to die).
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));
  for (Binary& b : binaries) {
    EXPECT_TRUE(b.process->running()) << b.name << " did not survive the datagrams: " << State(*b.process)
                                      << "\n" << b.process->Out() << b.process->Err();
  }

  // The web bridge still answers.
  EXPECT_NE(HttpStatusLine(web_port).find("200"), std::string::npos) << "snapthread-web after the attack";

  // The device ends its run normally; the viewer takes its screenshot after the attack.
  ASSERT_TRUE(device.Wait(40.0, &code)) << "snapthread-device did not end";
  EXPECT_EQ(code, 0) << "snapthread-device: " << State(device) << "\n" << device.Out();
  ASSERT_TRUE(viewer.Wait(90.0, &code)) << "snapthread-viewer did not end";
  EXPECT_EQ(code, 0) << "snapthread-viewer: " << State(viewer) << "\n" << viewer.Out() << viewer.Err();
  struct stat st {};
  ASSERT_EQ(stat(shot.c_str(), &st), 0) << "no screenshot: " << viewer.Err();
  EXPECT_GT(st.st_size, 1000);
  EXPECT_GT(static_cast<int64_t>(st.st_mtim.tv_sec) * 1000000 + st.st_mtim.tv_nsec / 1000, attack_end_us)
      << "the viewer's screenshot was taken before the attack ended";

  for (ChildProcess* p : {&web, &server}) p->Signal(SIGTERM);
  for (ChildProcess* p : {&web, &server}) {
    EXPECT_TRUE(p->WaitOrKill(15.0, &code, 2.0));
    EXPECT_EQ(code, 0) << p->Out();
  }
  logger.Signal(SIGINT);
  EXPECT_TRUE(logger.WaitOrKill(10.0, &code, 2.0));
  EXPECT_EQ(code, 0) << logger.Out();

  // The session went on after the attack, as the logger recorded it.
  const Recorded rec = ReadLog(log, channels, attack_end_us);
  auto after = [&](const std::string& channel) {
    const auto it = rec.events_after.find(channel);
    return it == rec.events_after.end() ? 0L : it->second;
  };
  // Rates over the device's ~8 s after the attack, far below the Release speeds (about 1 kHz
  // poses, 500 models/s, 60 shapes/s, 10 statuses/s), divided for a sanitized build.
  EXPECT_GT(after(channels.force_model), 500 / SpeedScale()) << "force models after the attack";
  EXPECT_GT(after(channels.device_state), 500 / SpeedScale()) << "poses after the attack";
  EXPECT_GT(after(channels.shape), 50 / SpeedScale()) << "shapes after the attack";
  EXPECT_GT(after(channels.solver_status), 10) << "statuses after the attack";
  EXPECT_GT(rec.models_before, 0) << "the device had models before the attack";
  EXPECT_GT(rec.models_after, rec.models_before) << "the device got models after the attack";

  // Every receiving binary's liblcm counted each malformed datagram (they all joined the
  // group, so each gets every datagram; at least `sent`, as a datagram from elsewhere on
  // this group would count too).
  const std::vector<std::pair<const char*, std::string>> outputs = {
      {"snapthread-server", ReadFile(dir + "/server.txt")},
      {"snapthread-device", ReadFile(dir + "/device.txt")},
      {"snapthread-viewer", ReadFile(dir + "/viewer_err.txt") + ReadFile(dir + "/viewer.txt")},
      {"snapthread-web", ReadFile(dir + "/web.txt")},
      {"snapthread-logger", ReadFile(dir + "/logger.txt")}};
  for (const auto& [name, text] : outputs) {
    const long counted = DroppedSinceStart(text);
    std::printf("%s: counted %ld of the %ld malformed datagrams\n", name, counted, sent);
    EXPECT_GE(counted, sent) << name << " did not count the " << sent << " malformed datagrams:\n"
                             << text;
  }
  std::printf("recorded after the attack: %ld force models, %ld poses, %ld shapes, %ld statuses; "
              "device models_received %lld before, %lld after\n",
              after(channels.force_model), after(channels.device_state), after(channels.shape),
              after(channels.solver_status), static_cast<long long>(rec.models_before),
              static_cast<long long>(rec.models_after));
}

}  // namespace
}  // namespace snapthread
