// libFuzzer target: liblcm's udpm receive path (the project's patched copy, built for this
// fuzz build by cmake/PatchedLcm.cmake). The input is a list of datagrams; each is sent as
// real UDP to an lcm_t in this process that listens on its own multicast group on loopback,
// so the bytes go through the kernel and then through lcm_udpm.c's read thread exactly as
// a stranger's would: header checks, fragment reassembly (lcm_frag_buf_store), short
// messages, dispatch to the handlers (lcm.c). Every channel has a handler (".*"), so any
// fragment 0 opens a reassembly buffer. The handler reads every byte LCM delivers, so a
// message longer than its buffer shows up under ASan.
//
// Input format, repeated: [sender] [len lo] [len hi] [len bytes]. `sender % 3` picks one of
// three sending sockets (three source ports: three reassembly buffers); a length past the
// end of the input takes what is left. After the datagrams a short message on a sentinel
// channel, with this run's number, is sent from each socket; the run ends when all three
// have been dispatched, so every datagram before them has been processed in this run
// (one socket, one read thread, datagrams in order).
//
// Needs a multicast route (deploy/multicast-route.sh). Seeds: tests/fuzz/corpus/lcm/.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include <lcm/lcm.h>

namespace {

// This fuzzer's group alone; a 2 MiB socket buffer (LCM warns below 256 KiB).
constexpr char kUrl[] = "udpm://239.255.76.93:7693?ttl=0&recv_buf_size=2097152";
constexpr char kGroup[] = "239.255.76.93";
constexpr int kPort = 7693;
constexpr char kSentinel[] = "SNAPTHREAD_FUZZ_SENTINEL";
constexpr int kSenders = 3;
constexpr size_t kMaxDatagram = 8192;

struct State {
  lcm_t* lcm = nullptr;
  int fds[kSenders] = {-1, -1, -1};
  sockaddr_in group{};
  uint32_t run = 0;
  int sentinels_seen = 0;
  volatile uint32_t sink = 0;
};

State& Global() {
  static State s;
  return s;
}

void OnMessage(const lcm_recv_buf_t* rbuf, const char* channel, void* user) {
  State& s = *static_cast<State*>(user);
  // Every byte LCM hands over is read: an out-of-bounds length is an ASan report.
  const auto* p = static_cast<const uint8_t*>(rbuf->data);
  uint32_t sum = 0;
  for (uint32_t i = 0; i < rbuf->data_size; ++i) sum += p[i];
  sum += static_cast<uint32_t>(std::strlen(channel));
  s.sink = s.sink + sum;
  uint32_t run = 0;
  if (std::strcmp(channel, kSentinel) == 0 && rbuf->data_size == sizeof(run)) {
    std::memcpy(&run, rbuf->data, sizeof(run));
    if (run == s.run) ++s.sentinels_seen;
  }
}

void SendTo(int fd, const sockaddr_in& to, const uint8_t* data, size_t size) {
  // A failed send (e.g. a full socket buffer) only loses that datagram, as on a network.
  (void)sendto(fd, data, size, 0, reinterpret_cast<const sockaddr*>(&to), sizeof(to));
}

// LCM's short message: "LC02", a sequence number, the channel, NUL, the payload.
void SendSentinel(int fd, const sockaddr_in& to, uint32_t run) {
  uint8_t b[64];
  const uint32_t magic = htonl(0x4c433032), seq = htonl(run);
  std::memcpy(b, &magic, 4);
  std::memcpy(b + 4, &seq, 4);
  std::memcpy(b + 8, kSentinel, sizeof(kSentinel));  // with its NUL
  std::memcpy(b + 8 + sizeof(kSentinel), &run, sizeof(run));
  SendTo(fd, to, b, 8 + sizeof(kSentinel) + sizeof(run));
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  State& s = Global();
  s.lcm = lcm_create(kUrl);
  lcm_subscription_t* sub = s.lcm ? lcm_subscribe(s.lcm, ".*", OnMessage, &s) : nullptr;
  if (!sub) {
    std::fprintf(stderr, "lcm_fuzzer: cannot receive on %s (no multicast route? "
                         "deploy/multicast-route.sh)\n", kUrl);
    std::abort();
  }
  // No limit on queued messages (LCM's default drops past 30), so no sentinel is dropped.
  lcm_subscription_set_queue_capacity(sub, 0);
  s.group.sin_family = AF_INET;
  s.group.sin_port = htons(kPort);
  inet_pton(AF_INET, kGroup, &s.group.sin_addr);
  for (int& fd : s.fds) {
    fd = socket(AF_INET, SOCK_DGRAM, 0);
    unsigned char ttl = 0, loop = 1;
    setsockopt(fd, IPPROTO_IP, IP_MULTICAST_TTL, &ttl, sizeof(ttl));
    setsockopt(fd, IPPROTO_IP, IP_MULTICAST_LOOP, &loop, sizeof(loop));
    if (fd < 0) std::abort();
  }
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  State& s = Global();
  size_t at = 0;
  while (at + 3 <= size) {
    const int sender = data[at] % kSenders;
    size_t len = static_cast<size_t>(data[at + 1]) | static_cast<size_t>(data[at + 2]) << 8;
    at += 3;
    if (len > size - at) len = size - at;
    if (len > kMaxDatagram) len = kMaxDatagram;
    SendTo(s.fds[sender], s.group, data + at, len);
    at += len;
  }
  ++s.run;
  s.sentinels_seen = 0;
  for (int fd : s.fds) SendSentinel(fd, s.group, s.run);
  // Each sentinel comes after its socket's datagrams; 5 s without one is a hang.
  for (int waited_ms = 0; s.sentinels_seen < kSenders;) {
    const int r = lcm_handle_timeout(s.lcm, 100);
    if (r < 0 && errno == EINTR) continue;  // libFuzzer's -timeout alarm
    if (r < 0) {
      std::fprintf(stderr, "lcm_fuzzer: lcm_handle_timeout failed: %s\n", std::strerror(errno));
      std::abort();
    }
    if (r == 0 && (waited_ms += 100) >= 5000) {
      std::fprintf(stderr, "lcm_fuzzer: the sentinels of run %u did not arrive in 5 s\n", s.run);
      std::abort();
    }
  }
  return 0;
}
