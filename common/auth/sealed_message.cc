#include "auth/sealed_message.h"

#include <atomic>
#include <cstring>
#include <memory>
#include <mutex>
#include <vector>

#include "auth/key_id.h"
#include "auth/message_mac.h"
#include "snapthread/sealed_t.hpp"

namespace snapthread::auth {

namespace {

constexpr std::string_view kSealDomain = "snapthread-seal-v1";
constexpr std::string_view kReadKeyLabel = "read";

struct SealState {
  SessionKey read;
  std::optional<SessionKey> previous;
  int64_t read_id = 0;
  int64_t previous_id = 0;
  bool seal_outgoing = false;
  bool seal_with_previous = false;
};

// Replaced states are kept, not freed: a reload happens a few times a session at most,
// and a thread may still be reading the old one. They stay reachable from this list (no
// leak), which only SetSealing touches, under its lock.
std::atomic<const SealState*> g_state{nullptr};
std::mutex g_states_mutex;
std::vector<std::unique_ptr<const SealState>>& States() {
  static auto* states = new std::vector<std::unique_ptr<const SealState>>();  // lives to the end
  return *states;
}

int64_t ReadKeyWireId(const SessionKey& key) { return KeyIdToWire(SecretKeyId(kReadKeyLabel, key)); }

// The associated data: domain, channel, key id.
struct Associated {
  uint8_t bytes[kSealDomain.size() + 4 + 256 + 8];
  std::size_t size = 0;
};

bool MakeAssociated(std::string_view channel, int64_t key_id, Associated* ad) {
  if (channel.size() > 256) return false;
  uint8_t* p = ad->bytes;
  std::memcpy(p, kSealDomain.data(), kSealDomain.size());
  p += kSealDomain.size();
  const auto n = static_cast<uint32_t>(channel.size());
  for (int i = 3; i >= 0; --i) *p++ = static_cast<uint8_t>(n >> (8 * i));
  std::memcpy(p, channel.data(), channel.size());
  p += channel.size();
  const auto id = static_cast<uint64_t>(key_id);
  for (int i = 0; i < 8; ++i) *p++ = static_cast<uint8_t>(id >> (8 * i));
  ad->size = static_cast<std::size_t>(p - ad->bytes);
  return true;
}

struct ThreadBuffers {
  sealed_t envelope;
  std::vector<uint8_t> out;
  std::vector<uint8_t> plain;
};

ThreadBuffers& Buffers() {
  thread_local ThreadBuffers buffers;
  return buffers;
}

bool Grow(std::vector<uint8_t>* v, std::size_t n) {
  try {
    if (n > v->capacity()) v->reserve(2 * n);
    v->resize(n);
    return true;
  } catch (...) {
    return false;
  }
}

}  // namespace

void SetSealing(const SessionKey& read_key, const SessionKey* previous, bool seal_outgoing,
                bool seal_with_previous) {
  auto state = std::make_unique<SealState>(SealState{SessionKey::FromBytes(read_key.data(), SessionKey::kBytes), std::nullopt});
  SealState* s = state.get();
  s->read_id = ReadKeyWireId(s->read);
  if (previous != nullptr) {
    s->previous.emplace(SessionKey::FromBytes(previous->data(), SessionKey::kBytes));
    s->previous_id = ReadKeyWireId(*s->previous);
  }
  s->seal_outgoing = seal_outgoing;
  s->seal_with_previous = seal_with_previous && previous != nullptr;
  std::lock_guard<std::mutex> lock(g_states_mutex);
  States().push_back(std::move(state));
  g_state.store(s, std::memory_order_release);
}

void ClearSealing() { g_state.store(nullptr, std::memory_order_release); }

bool SealingOutgoing() noexcept {
  const SealState* s = g_state.load(std::memory_order_acquire);
  return s != nullptr && s->seal_outgoing;
}

ByteView SealForChannel(ByteView encoded, std::string_view channel) noexcept {
  const SealState* s = g_state.load(std::memory_order_acquire);
  if (s == nullptr || !s->seal_outgoing) return encoded;
  const SessionKey& key = s->seal_with_previous ? *s->previous : s->read;
  const int64_t key_id = s->seal_with_previous ? s->previous_id : s->read_id;
  if (encoded.size > kMaxMacMessageBytes) return {};
  Associated ad;
  if (!MakeAssociated(channel, key_id, &ad)) return {};
  ThreadBuffers& b = Buffers();
  const std::size_t sealed_size = encoded.size + kAeadOverheadBytes;
  try {
    if (sealed_size > b.envelope.sealed.capacity()) b.envelope.sealed.reserve(2 * sealed_size);
    b.envelope.sealed.resize(sealed_size);
  } catch (...) {
    return {};
  }
  std::size_t written = 0;
  if (!Seal(key, encoded, ByteView{ad.bytes, ad.size}, b.envelope.sealed.data(), sealed_size, &written)) {
    return {};
  }
  b.envelope.read_key_id = key_id;
  b.envelope.size = static_cast<int32_t>(written);
  const int n = b.envelope.getEncodedSize();
  if (n <= 0 || !Grow(&b.out, static_cast<std::size_t>(n))) return {};
  if (b.envelope.encode(b.out.data(), 0, n) != n) return {};
  return ByteView{b.out.data(), static_cast<std::size_t>(n)};
}

bool IsSealed(const void* data, std::size_t size) noexcept {
  if (data == nullptr || size < 8) return false;
  int64_t hash = 0;
  if (__int64_t_decode_array(data, 0, static_cast<int>(size), &hash, 1) != 8) return false;
  return hash == sealed_t::getHash();
}

namespace {

std::optional<ByteView> OpenWith(const SessionKey& key, int64_t key_id, const sealed_t& envelope,
                                 std::string_view channel) {
  Associated ad;
  if (!MakeAssociated(channel, key_id, &ad)) return std::nullopt;
  ThreadBuffers& b = Buffers();
  const std::size_t sealed_size = envelope.sealed.size();
  if (sealed_size < kAeadOverheadBytes || sealed_size > kMaxMacMessageBytes + kAeadOverheadBytes) {
    return std::nullopt;
  }
  if (!Grow(&b.plain, sealed_size - kAeadOverheadBytes)) return std::nullopt;
  std::size_t opened = 0;
  if (!Open(key, ByteView{envelope.sealed.data(), sealed_size}, ByteView{ad.bytes, ad.size},
            b.plain.data(), b.plain.size(), &opened)) {
    return std::nullopt;
  }
  return ByteView{b.plain.data(), opened};
}

// Decodes the envelope exactly (no trailing bytes) into the thread's object.
const sealed_t* DecodeEnvelope(const void* data, std::size_t size) {
  if (!IsSealed(data, size) || size > kMaxMacMessageBytes + 64) return nullptr;
  ThreadBuffers& b = Buffers();
  try {
    if (b.envelope.decode(data, 0, static_cast<int>(size)) != static_cast<int>(size)) return nullptr;
  } catch (...) {
    return nullptr;
  }
  if (b.envelope.size < 0 || static_cast<std::size_t>(b.envelope.size) != b.envelope.sealed.size()) return nullptr;
  return &b.envelope;
}

}  // namespace

std::optional<ByteView> OpenSealed(const void* data, std::size_t size, std::string_view channel) noexcept {
  const SealState* s = g_state.load(std::memory_order_acquire);
  if (s == nullptr) return std::nullopt;
  const sealed_t* envelope = DecodeEnvelope(data, size);
  if (envelope == nullptr) return std::nullopt;
  if (envelope->read_key_id == s->read_id) return OpenWith(s->read, s->read_id, *envelope, channel);
  if (s->previous && envelope->read_key_id == s->previous_id) {
    return OpenWith(*s->previous, s->previous_id, *envelope, channel);
  }
  return std::nullopt;
}

std::optional<ByteView> OpenSealedWith(const SessionKey& read_key, const void* data, std::size_t size,
                                       std::string_view channel) noexcept {
  const sealed_t* envelope = DecodeEnvelope(data, size);
  if (envelope == nullptr) return std::nullopt;
  const int64_t id = ReadKeyWireId(read_key);
  if (envelope->read_key_id != id) return std::nullopt;
  return OpenWith(read_key, id, *envelope, channel);
}

}  // namespace snapthread::auth
