// snapthread-fragment-sender: a stranger's raw UDP datagrams in LCM's wire format (no
// liblcm), sent to an LCM udpm group: the two-fragment crash of liblcm 1.3.1 (fragment 0
// of a message on a subscribed channel, then fragment 1 at offset 0xFFFFFFF0) on every
// channel of a session, and further malformed datagrams (offset and size past or around
// 2^32, fragment count 0 or huge, fragment number past the count, a declared size over
// LCM's maximum, truncated headers, unterminated channel names, a bad magic).
//
// Usage: snapthread-fragment-sender LCM_URL SESSION [ROUNDS] [PAUSE_MS]
// Prints "sent N malformed datagrams (C crash pairs) in R rounds": N counts the datagrams a
// receiver must drop as malformed (every fragment 0 of a crash pair is well formed).
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <regex>
#include <string>
#include <thread>
#include <vector>

namespace {

using Bytes = std::vector<uint8_t>;

constexpr uint32_t kMagicShort = 0x4c433032;  // "LC02": one datagram, one message
constexpr uint32_t kMagicLong = 0x4c433033;   // "LC03": one fragment of a message
constexpr char kPayloadByte = 0x5A;

void PutU32(Bytes* b, uint32_t v) {
  const uint32_t n = htonl(v);
  const auto* p = reinterpret_cast<const uint8_t*>(&n);
  b->insert(b->end(), p, p + 4);
}
void PutU16(Bytes* b, uint16_t v) {
  const uint16_t n = htons(v);
  const auto* p = reinterpret_cast<const uint8_t*>(&n);
  b->insert(b->end(), p, p + 2);
}

struct Fragment {
  uint32_t seqno = 1;
  uint32_t msg_size = 1024;
  uint32_t offset = 0;
  uint16_t fragment_no = 0;
  uint16_t fragments_in_msg = 2;
  std::string channel;  // written (NUL-terminated) in fragment 0 only
  bool terminate_channel = true;
  size_t payload = 16;
};

// The 20-byte long header, the channel in fragment 0, then the payload.
Bytes LongDatagram(const Fragment& f) {
  Bytes b;
  PutU32(&b, kMagicLong);
  PutU32(&b, f.seqno);
  PutU32(&b, f.msg_size);
  PutU32(&b, f.offset);
  PutU16(&b, f.fragment_no);
  PutU16(&b, f.fragments_in_msg);
  if (f.fragment_no == 0) {
    b.insert(b.end(), f.channel.begin(), f.channel.end());
    if (f.terminate_channel) b.push_back(0);
  }
  b.insert(b.end(), f.payload, static_cast<uint8_t>(kPayloadByte));
  return b;
}

// A short (LC02) datagram whose channel name runs to the end of the datagram.
Bytes UnterminatedShort(const std::string& channel) {
  Bytes b;
  PutU32(&b, kMagicShort);
  PutU32(&b, 7);
  b.insert(b.end(), channel.begin(), channel.end());
  return b;
}

class Sender {
 public:
  Sender(const std::string& group, int port) {
    fd_ = socket(AF_INET, SOCK_DGRAM, 0);
    unsigned char ttl = 0;  // this host only, as the tests' ttl=0 URL
    unsigned char loop = 1;
    setsockopt(fd_, IPPROTO_IP, IP_MULTICAST_TTL, &ttl, sizeof(ttl));
    setsockopt(fd_, IPPROTO_IP, IP_MULTICAST_LOOP, &loop, sizeof(loop));
    std::memset(&to_, 0, sizeof(to_));
    to_.sin_family = AF_INET;
    to_.sin_port = htons(static_cast<uint16_t>(port));
    ok_ = fd_ >= 0 && inet_pton(AF_INET, group.c_str(), &to_.sin_addr) == 1;
  }
  ~Sender() {
    if (fd_ >= 0) close(fd_);
  }
  bool ok() const { return ok_; }
  bool Send(const Bytes& b) {
    const ssize_t n = sendto(fd_, b.data(), b.size(), 0, reinterpret_cast<const sockaddr*>(&to_),
                             sizeof(to_));
    // Paced, so that no receiver's socket buffer drops what it must count.
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
    if (n != static_cast<ssize_t>(b.size())) {
      std::perror("snapthread-fragment-sender: sendto");
      return false;
    }
    return true;
  }

 private:
  int fd_ = -1;
  sockaddr_in to_{};
  bool ok_ = false;
};

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3 || argc > 5) {
    std::fprintf(stderr, "usage: %s LCM_URL SESSION [ROUNDS] [PAUSE_MS]\n", argv[0]);
    return 2;
  }
  std::smatch m;
  const std::string url = argv[1];
  if (!std::regex_search(url, m, std::regex(R"(^udpm://([0-9.]+):([0-9]+))"))) {
    std::fprintf(stderr, "snapthread-fragment-sender: %s is no udpm://GROUP:PORT URL\n", argv[1]);
    return 2;
  }
  const std::string session = argv[2];
  const int rounds = argc > 3 ? std::atoi(argv[3]) : 1;
  const int pause_ms = argc > 4 ? std::atoi(argv[4]) : 200;
  Sender sender(m[1], std::stoi(m[2]));
  if (!sender.ok()) {
    std::fprintf(stderr, "snapthread-fragment-sender: no socket for %s\n", argv[1]);
    return 1;
  }
  const std::vector<std::string> channels = {
      session + "_DEVICE_STATE", session + "_FORCE_MODEL",   session + "_SHAPE",
      session + "_SOLVER_STATUS", session + "_DEVICE_STATUS", session + "_COMMAND"};

  long malformed = 0, pairs = 0;
  bool ok = true;
  uint32_t seq = static_cast<uint32_t>(getpid()) << 8;
  auto bad = [&](const Bytes& b) {
    ok = sender.Send(b) && ok;
    ++malformed;
  };
  for (int r = 0; r < rounds; ++r) {
    for (const std::string& channel : channels) {
      // The crash of issue 23: a well-formed fragment 0 makes a subscribed receiver keep a
      // 1,024-byte reassembly buffer; fragment 1 at 0xFFFFFFF0 with 16 bytes wraps
      // offset + size to 0 in 32 bits.
      Fragment f0{.seqno = ++seq, .channel = channel};
      ok = sender.Send(LongDatagram(f0)) && ok;
      Fragment f1 = f0;
      f1.fragment_no = 1;
      f1.offset = 0xFFFFFFF0u;
      bad(LongDatagram(f1));
      ++pairs;
      // Offset + size = 2^32 + 1 (wraps to 1), and a plain overrun (1,000 + 100 > 1,024).
      f1.offset = 0xFFFFFFFFu;
      f1.payload = 2;
      bad(LongDatagram(f1));
      f1.offset = 1000;
      f1.payload = 100;
      bad(LongDatagram(f1));
      // Fragment 0 of the same message again, its payload past the declared size.
      Fragment big0{.seqno = ++seq, .msg_size = 64, .channel = channel, .payload = 200};
      bad(LongDatagram(big0));
    }
    const std::string& channel = channels[static_cast<size_t>(r) % channels.size()];
    // Fragment counts: 0, huge for the size, a number past the count, too few for the size.
    bad(LongDatagram({.seqno = ++seq, .fragments_in_msg = 0, .channel = channel}));
    bad(LongDatagram({.seqno = ++seq, .fragments_in_msg = 65535, .channel = channel}));
    bad(LongDatagram({.seqno = ++seq, .fragment_no = 3, .fragments_in_msg = 2, .channel = channel}));
    bad(LongDatagram({.seqno = ++seq, .msg_size = 10u << 20, .fragments_in_msg = 1, .channel = channel}));
    // Declared sizes over LCM's maximum (2^28 bytes), one of them 4 GiB - 1.
    bad(LongDatagram({.seqno = ++seq, .msg_size = (1u << 28) + 1, .fragments_in_msg = 4200,
                      .channel = channel}));
    bad(LongDatagram({.seqno = ++seq, .msg_size = 0xFFFFFFFFu, .fragments_in_msg = 65535,
                      .channel = channel}));
    // Truncated headers: a long header of 12 and 19 bytes, a short one of 5.
    Bytes whole = LongDatagram({.seqno = ++seq, .channel = channel});
    bad(Bytes(whole.begin(), whole.begin() + 12));
    bad(Bytes(whole.begin(), whole.begin() + 19));
    bad(Bytes(whole.begin(), whole.begin() + 5));
    // Channel names that do not end inside the datagram (fragment 0 and a short message),
    // and one of 64 characters.
    bad(LongDatagram({.seqno = ++seq, .channel = channel, .terminate_channel = false, .payload = 0}));
    bad(UnterminatedShort(channel));
    bad(LongDatagram({.seqno = ++seq, .channel = channel + std::string(64, 'X')}));
    // Not LCM at all.
    bad(Bytes(100, 0xEE));
    std::this_thread::sleep_for(std::chrono::milliseconds(pause_ms));
  }
  std::printf("sent %ld malformed datagrams (%ld crash pairs) in %d rounds\n", malformed, pairs,
              rounds);
  return ok ? 0 : 1;
}
