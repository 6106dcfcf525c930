// snapthread-auth-bench: the median cost of the roles' primitives on a 200-byte message
// (docs/security.md, "Roles: the key hierarchy"), to choose which one a message stream can
// afford: MAC (crypto_auth, through auth/file_mac.h), Ed25519 sign and verify, AEAD seal
// and open, a key ring lookup, a device key derivation; plus the MAC of a whole force model
// as the device checks it today. Built with SNAPTHREAD_BUILD_EXTRAS; no test runs it.
//
// Each primitive runs kBatches batches of kCalls calls; the figure is the median batch's
// time per call (the minimum in brackets), so other processes on a shared machine shift
// the spread more than the median.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include <unistd.h>

#include "auth/aead.h"
#include "auth/file_mac.h"
#include "auth/key_ring.h"
#include "auth/message_mac.h"
#include "auth/role_keys.h"
#include "auth/signature.h"
#include "snapthread/force_model_t.hpp"

namespace {

using namespace snapthread::auth;

constexpr int kBatches = 31;
constexpr int kCalls = 500;

int g_sink = 0;  // keeps results alive (printed at the end)

void Measure(const char* name, const std::function<void()>& call) {
  for (int i = 0; i < kCalls / 10; ++i) call();  // warm-up
  std::vector<double> ns;
  for (int b = 0; b < kBatches; ++b) {
    const auto t0 = std::chrono::steady_clock::now();
    for (int i = 0; i < kCalls; ++i) call();
    const auto t1 = std::chrono::steady_clock::now();
    ns.push_back(std::chrono::duration<double, std::nano>(t1 - t0).count() / kCalls);
  }
  std::sort(ns.begin(), ns.end());
  std::printf("%-34s %9.0f ns  [min %.0f]\n", name, ns[ns.size() / 2], ns.front());
}

std::string LoadAverage() {
  std::ifstream in("/proc/loadavg");
  std::string one, five, fifteen;
  in >> one >> five >> fifteen;
  return one + " " + five + " " + fifteen;
}

}  // namespace

int main() {
  const std::time_t now = std::time(nullptr);
  char date[32];
  std::strftime(date, sizeof date, "%Y-%m-%d %H:%M UTC", std::gmtime(&now));
  std::printf("snapthread-auth-bench %s, %ld cores, load average before %s\n", date,
              sysconf(_SC_NPROCESSORS_ONLN), LoadAverage().c_str());
  std::printf("median ns per call on a 200-byte message (%d batches of %d calls)\n", kBatches, kCalls);

  const SessionKey root = SessionKey::Generate();
  const SessionKey device = DeriveDeviceKey(root, "left", 0);
  const Signer signer = DeriveServerSigner(root);
  const SignatureVerifier verifier(signer.public_key());
  const SessionKey read_key = DeriveReadKey(root);
  std::vector<uint8_t> message(200, 0x5a), sealed(200 + kAeadOverheadBytes), plain(200);
  const uint8_t ad[] = "SNAPTHREAD_FORCE_MODEL";
  uint8_t tag[kFileMacBytes];
  uint8_t sig[kSignatureBytes];
  std::size_t sealed_size = 0, plain_size = 0;

  Measure("MAC (crypto_auth) compute", [&] {
    FileMac("bench", message.data(), message.size(), device, tag);
    g_sink += tag[0];
  });
  Measure("MAC (crypto_auth) verify", [&] {
    g_sink += VerifyFileMac("bench", message.data(), message.size(), device, tag) ? 1 : 0;
  });
  Measure("Ed25519 sign", [&] {
    signer.Sign(message.data(), message.size(), sig);
    g_sink += sig[0];
  });
  Measure("Ed25519 verify", [&] { g_sink += verifier.Verify(message.data(), message.size(), sig) ? 1 : 0; });
  Measure("AEAD seal (XChaCha20-Poly1305)", [&] {
    g_sink += Seal(read_key, {message.data(), message.size()}, {ad, sizeof ad}, sealed.data(), sealed.size(),
                   &sealed_size) ? 1 : 0;
  });
  Measure("AEAD open (XChaCha20-Poly1305)", [&] {
    g_sink += Open(read_key, {sealed.data(), sealed_size}, {ad, sizeof ad}, plain.data(), plain.size(),
                   &plain_size) ? 1 : 0;
  });

  KeyRing ring(SessionKey::FromBytes(root.data(), SessionKey::kBytes));
  const KeyId left = SecretKeyId("device", device);
  Measure("key ring lookup (cached)", [&] {
    g_sink += ring.Resolve(Role::kDevice, "left", 0, left, 1).verdict == KeyVerdict::kAccepted ? 1 : 0;
  });
  Measure("device key derivation", [&] { g_sink += DeriveDeviceKey(root, "left", 0).data()[0]; });

  snapthread::force_model_t model{};
  int64_t seq = 0;
  std::vector<uint8_t> encoded;
  Measure("force model MAC sign (today)", [&] { g_sink += Sign(&model, "FORCE_MODEL", 1, ++seq, device) ? 1 : 0; });
  encoded.resize(static_cast<std::size_t>(model.getEncodedSize()));
  model.encode(encoded.data(), 0, static_cast<int>(encoded.size()));
  Measure("force model MAC verify (today)", [&] {
    g_sink += VerifyEncoded(encoded.data(), encoded.size(), "FORCE_MODEL", device) ? 1 : 0;
  });
  std::printf("force model: %zu bytes encoded; load average after %s (check %d)\n", encoded.size(),
              LoadAverage().c_str(), g_sink & 1);
  return 0;
}
