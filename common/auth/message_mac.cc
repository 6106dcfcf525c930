#include "auth/message_mac.h"

#include <sodium.h>

#include <cstdint>
#include <cstring>
#include <vector>

namespace snapthread::auth {

static_assert(kMacBytes == crypto_auth_BYTES);

namespace {

constexpr std::string_view kDomain = "snapthread-mac-v1";

struct MacBuffer {
  std::vector<uint8_t> bytes;
  std::size_t prefix = 0;  // bytes before the message part
};

MacBuffer& ThreadBuffer() {
  thread_local MacBuffer buffer;
  return buffer;
}

}  // namespace

namespace detail {

uint8_t* PrepareMacBuffer(std::string_view channel, std::size_t message_bytes) noexcept {
  if (message_bytes > kMaxMacMessageBytes || channel.size() > UINT32_MAX) return nullptr;
  MacBuffer& b = ThreadBuffer();
  const auto channel_len = static_cast<uint32_t>(channel.size());
  b.prefix = kDomain.size() + 4 + channel.size();
  const std::size_t total = b.prefix + message_bytes;
  // Grows geometrically and never shrinks: steady state is allocation-free.
  try {
    if (total > b.bytes.capacity()) b.bytes.reserve(2 * total);
    b.bytes.resize(total);
  } catch (...) {
    return nullptr;
  }
  uint8_t* p = b.bytes.data();
  std::memcpy(p, kDomain.data(), kDomain.size());
  p += kDomain.size();
  for (int i = 3; i >= 0; --i) *p++ = static_cast<uint8_t>(channel_len >> (8 * i));
  std::memcpy(p, channel.data(), channel.size());
  return b.bytes.data() + b.prefix;
}

void ComputeMac(std::size_t message_bytes, const SessionKey& key, uint8_t tag[kMacBytes]) {
  const MacBuffer& b = ThreadBuffer();
  crypto_auth(tag, b.bytes.data(), b.prefix + message_bytes, key.data());
}

}  // namespace detail

bool VerifyEncoded(const void* data, std::size_t size, std::string_view channel,
                   const SessionKey& key) {
  // Shorter than a type fingerprint and a tag: not a signed snapthread message.
  if (data == nullptr || size < 8 + kMacBytes) return false;
  uint8_t* bytes = detail::PrepareMacBuffer(channel, size);
  if (bytes == nullptr) return false;
  std::memcpy(bytes, data, size);
  uint8_t tag[kMacBytes];
  std::memcpy(tag, bytes + size - kMacBytes, kMacBytes);
  std::memset(bytes + size - kMacBytes, 0, kMacBytes);
  const MacBuffer& b = ThreadBuffer();
  return crypto_auth_verify(tag, b.bytes.data(), b.prefix + size, key.data()) == 0;
}

}  // namespace snapthread::auth
