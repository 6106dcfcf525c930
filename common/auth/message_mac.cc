#include "auth/message_mac.h"

#include <sodium.h>

#include <cstdint>
#include <cstring>
#include <vector>

namespace snapthread::auth {

static_assert(kMacBytes == crypto_auth_BYTES);
static_assert(kSignatureBytes == crypto_sign_BYTES);

namespace {

constexpr std::string_view kMacDomain = "snapthread-mac-v2";
constexpr std::string_view kSigDomain = "snapthread-sig-v1";
static_assert(kMacDomain.size() == kSigDomain.size(), "the prefix is rewritten in place");

struct TagBuffer {
  std::vector<uint8_t> bytes;
  std::size_t prefix = 0;  // bytes before the message part
};

TagBuffer& ThreadBuffer() {
  thread_local TagBuffer buffer;
  return buffer;
}

void SetDomain(std::string_view domain) {
  std::memcpy(ThreadBuffer().bytes.data(), domain.data(), domain.size());
}

// The buffer's message of `size` bytes: its tag slots.
uint8_t* Tags(std::size_t size) {
  TagBuffer& b = ThreadBuffer();
  return b.bytes.data() + b.prefix + size - kTagBytes;
}

bool IsZero(const uint8_t* bytes, std::size_t n) { return sodium_is_zero(bytes, n) == 1; }

// Copies a received buffer into the thread's buffer; nullptr when it cannot hold a trailer.
uint8_t* Receive(const void* data, std::size_t size, std::string_view channel) {
  // Shorter than a type fingerprint and the tags: not a tagged snapthread message.
  if (data == nullptr || size < 8 + kTagBytes) return nullptr;
  uint8_t* bytes = detail::PrepareTagBuffer(channel, size);
  if (bytes == nullptr) return nullptr;
  std::memcpy(bytes, data, size);
  return bytes;
}

}  // namespace

int64_t KeyIdToWire(const KeyId& id) {
  uint64_t v = 0;
  for (std::size_t i = 0; i < kKeyIdBytes; ++i) v |= uint64_t{id[i]} << (8 * i);
  return static_cast<int64_t>(v);
}

KeyId KeyIdFromWire(int64_t wire) {
  const auto v = static_cast<uint64_t>(wire);
  KeyId id{};
  for (std::size_t i = 0; i < kKeyIdBytes; ++i) id[i] = static_cast<uint8_t>(v >> (8 * i));
  return id;
}

namespace detail {

uint8_t* PrepareTagBuffer(std::string_view channel, std::size_t message_bytes) noexcept {
  if (message_bytes > kMaxMacMessageBytes || channel.size() > UINT32_MAX) return nullptr;
  TagBuffer& b = ThreadBuffer();
  const auto channel_len = static_cast<uint32_t>(channel.size());
  b.prefix = kMacDomain.size() + 4 + channel.size();
  const std::size_t total = b.prefix + message_bytes;
  // Grows geometrically and never shrinks: steady state is allocation-free.
  try {
    if (total > b.bytes.capacity()) b.bytes.reserve(2 * total);
    b.bytes.resize(total);
  } catch (...) {
    return nullptr;
  }
  uint8_t* p = b.bytes.data() + kMacDomain.size();
  for (int i = 3; i >= 0; --i) *p++ = static_cast<uint8_t>(channel_len >> (8 * i));
  std::memcpy(p, channel.data(), channel.size());
  return b.bytes.data() + b.prefix;
}

void ApplyTags(std::size_t message_bytes, const Tagger& tagger) noexcept {
  TagBuffer& b = ThreadBuffer();
  uint8_t* tags = Tags(message_bytes);
  const std::size_t total = b.prefix + message_bytes;
  if (tagger.signer != nullptr || tagger.previous_signer != nullptr) {
    SetDomain(kSigDomain);
    uint8_t sig[kSignatureBytes];
    uint8_t sig2[kSignatureBytes] = {};
    if (tagger.signer != nullptr) tagger.signer->Sign(b.bytes.data(), total, sig);
    else std::memset(sig, 0, sizeof sig);
    if (tagger.previous_signer != nullptr) tagger.previous_signer->Sign(b.bytes.data(), total, sig2);
    std::memcpy(tags, sig, kSignatureBytes);
    std::memcpy(tags + kSignatureBytes, sig2, kSignatureBytes);
  }
  if (tagger.mac_key != nullptr) {
    SetDomain(kMacDomain);
    crypto_auth(tags + 2 * kSignatureBytes, b.bytes.data(), total, tagger.mac_key->data());
  }
}

}  // namespace detail

bool VerifyMac(const void* data, std::size_t size, std::string_view channel, const SessionKey& key) {
  uint8_t* bytes = Receive(data, size, channel);
  if (bytes == nullptr) return false;
  uint8_t* mac = Tags(size) + 2 * kSignatureBytes;
  uint8_t tag[kMacBytes];
  std::memcpy(tag, mac, kMacBytes);
  if (IsZero(tag, kMacBytes)) return false;
  std::memset(mac, 0, kMacBytes);
  SetDomain(kMacDomain);
  const TagBuffer& b = ThreadBuffer();
  return crypto_auth_verify(tag, b.bytes.data(), b.prefix + size, key.data()) == 0;
}

bool VerifySignature(const void* data, std::size_t size, std::string_view channel,
                     const PublicKey& key) {
  uint8_t* bytes = Receive(data, size, channel);
  if (bytes == nullptr) return false;
  uint8_t* tags = Tags(size);
  uint8_t sigs[2][kSignatureBytes];
  std::memcpy(sigs[0], tags, kSignatureBytes);
  std::memcpy(sigs[1], tags + kSignatureBytes, kSignatureBytes);
  std::memset(tags, 0, kTagBytes);
  SetDomain(kSigDomain);
  const TagBuffer& b = ThreadBuffer();
  const SignatureVerifier verifier(key);
  for (const auto& sig : sigs) {
    if (IsZero(sig, kSignatureBytes)) continue;
    if (verifier.Verify(b.bytes.data(), b.prefix + size, sig)) return true;
  }
  return false;
}

}  // namespace snapthread::auth
