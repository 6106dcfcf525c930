// snapthread-auth-bench: the median cost of the roles' primitives on a 200-byte message
// (docs/security.md, "Roles: the key hierarchy"): MAC (crypto_auth, through
// auth/file_mac.h), Ed25519 sign and verify, AEAD seal and open, a key ring lookup, a
// device key derivation; then, per channel at its rate, what tagging and checking a whole
// message costs (auth::Sign with the role's Tagger, VerifyMac, VerifySignature, the device
// certificate) in µs per message and in % of one core (docs/security.md, "Costs").
// Built with SNAPTHREAD_BUILD_EXTRAS; no test runs it.
//
// Each primitive runs kBatches batches of kCalls calls; the figure is the median batch's
// time per call (the minimum in brackets), so other processes on a shared machine shift
// the spread more than the median.
#include <algorithm>
#include <cstdlib>
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
#include "auth/device_certificate.h"
#include "auth/key_ring.h"
#include "auth/key_set.h"
#include "auth/message_mac.h"
#include "auth/role_keys.h"
#include "auth/signature.h"
#include "snapthread/device_state_t.hpp"
#include "snapthread/device_status_t.hpp"
#include "snapthread/force_model_t.hpp"
#include "snapthread/solver_status_t.hpp"
#include "snapthread/thread_shape_t.hpp"

namespace {

using namespace snapthread::auth;

constexpr int kBatches = 31;
constexpr int kCalls = 500;
constexpr int kShapeNodes = 200;  // a shape of the rod scenes' size (nodes)

int g_sink = 0;  // keeps results alive (printed at the end)

// Median ns per call over kBatches batches (printed with the fastest batch).
double Measure(const char* name, const std::function<void()>& call) {
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
  return ns[ns.size() / 2];
}

// One row of the per-channel table: `call` tags or checks one encoded message of
// `bytes` bytes, `rate_hz` times a second on `side`.
void ChannelRow(const char* channel, double rate_hz, const char* what, const char* side, std::size_t bytes,
                const std::function<void()>& call) {
  const std::string name = std::string(channel) + " " + what;
  const double ns = Measure(name.c_str(), call);
  std::printf("| %s | %g Hz | %s | %s | %zu | %.1f | %.3f |\n", channel, rate_hz, what, side, bytes, ns / 1e3,
              ns * rate_hz / 1e9 * 100.0);
}

// The encoding of `msg` (tags in place), for the receivers' checks.
template <class Msg>
std::vector<uint8_t> Encoded(const Msg& msg) {
  std::vector<uint8_t> bytes(static_cast<std::size_t>(msg.getEncodedSize()));
  msg.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  return bytes;
}

// The server's tagger for `device`'s force models: a MAC under the device's key, and the
// server's signature when `with_signature`.
Tagger ForceModelTagger(const KeySet& server, const KeySet& device, bool with_signature) {
  Tagger t = device.ForceModelTagger();
  t.signer = with_signature ? server.tagger().signer : nullptr;
  return t;
}

// Per channel at its rate: tagging on the sender, checking on the receiver.
void ChannelCosts(const SessionKey& root) {
  const KeySet server = KeySet::ForRole(root, Role::kServer);
  const KeySet device = KeySet::ForRole(root, Role::kDevice, "hand");
  const KeySet observer = KeySet::ForRole(root, Role::kObserver);
  const SessionKey& device_key = *device.mac_key();
  const PublicKey& server_pk = observer.server_public_key();
  int64_t seq = 0;
  std::printf("\n| channel | rate | work | side | bytes | µs/message | %% of a core |\n|---|---|---|---|---|---|---|\n");

  snapthread::device_state_t pose{};
  pose.device_id = "hand";
  const char* kPose = "SNAPTHREAD_DEVICE_STATE";
  if (!Sign(&pose, kPose, 1, ++seq, device.tagger())) std::abort();
  std::vector<uint8_t> bytes = Encoded(pose);
  ChannelRow("pose", 1000, "MAC sign", "device", bytes.size(),
             [&] { g_sink += Sign(&pose, kPose, 1, ++seq, device.tagger()) ? 1 : 0; });
  if (!Sign(&pose, kPose, 1, ++seq, device.tagger())) std::abort();
  bytes = Encoded(pose);
  ChannelRow("pose", 1000, "MAC verify", "server", bytes.size(),
             [&] { g_sink += VerifyMac(bytes.data(), bytes.size(), kPose, device_key) ? 1 : 0; });

  snapthread::force_model_t model{};
  const char* kModel = "SNAPTHREAD_FORCE_MODEL";
  const Tagger mac_only = ForceModelTagger(server, device, false);
  const Tagger mac_and_sig = ForceModelTagger(server, device, true);
  if (!Sign(&model, kModel, 1, ++seq, mac_and_sig)) std::abort();
  bytes = Encoded(model);
  ChannelRow("force model", 1000, "MAC sign", "server", bytes.size(),
             [&] { g_sink += Sign(&model, kModel, 1, ++seq, mac_only) ? 1 : 0; });
  ChannelRow("force model", 1000, "MAC verify", "device (off the servo thread)", bytes.size(),
             [&] { g_sink += VerifyMac(bytes.data(), bytes.size(), kModel, device_key) ? 1 : 0; });
  ChannelRow("force model", 60, "MAC + signature sign", "server", bytes.size(),
             [&] { g_sink += Sign(&model, kModel, 1, ++seq, mac_and_sig) ? 1 : 0; });
  ChannelRow("force model", 60, "signature verify", "observer", bytes.size(),
             [&] { g_sink += VerifySignature(bytes.data(), bytes.size(), kModel, server_pk) ? 1 : 0; });

  snapthread::thread_shape_t shape{};
  shape.scene = "zeeman";
  shape.model = "curve2d";
  shape.num_nodes = kShapeNodes;
  for (int i = 0; i < shape.num_nodes; ++i) shape.positions.push_back({0.01 * i, 0.0, 0.0});
  const char* kShape = "SNAPTHREAD_SHAPE";
  if (!Sign(&shape, kShape, 1, ++seq, server.tagger())) std::abort();
  bytes = Encoded(shape);
  ChannelRow("shape", 60, "signature sign", "server", bytes.size(),
             [&] { g_sink += Sign(&shape, kShape, 1, ++seq, server.tagger()) ? 1 : 0; });
  ChannelRow("shape", 60, "signature verify", "observer", bytes.size(),
             [&] { g_sink += VerifySignature(bytes.data(), bytes.size(), kShape, server_pk) ? 1 : 0; });

  snapthread::solver_status_t status{};
  status.scene = "zeeman";
  status.method = "newton";
  status.refusals = "device/bad-mac=12 observer/no-credential=3";
  const char* kStatus = "SNAPTHREAD_SOLVER_STATUS";
  if (!Sign(&status, kStatus, 1, ++seq, server.tagger())) std::abort();
  bytes = Encoded(status);
  ChannelRow("solver status", 10, "signature sign", "server", bytes.size(),
             [&] { g_sink += Sign(&status, kStatus, 1, ++seq, server.tagger()) ? 1 : 0; });
  ChannelRow("solver status", 10, "signature verify", "observer, device, ctl", bytes.size(),
             [&] { g_sink += VerifySignature(bytes.data(), bytes.size(), kStatus, server_pk) ? 1 : 0; });

  snapthread::device_status_t dstatus{};
  dstatus.device_id = "hand";
  std::copy(device.device_public_key()->begin(), device.device_public_key()->end(), dstatus.device_public_key);
  std::copy(device.device_certificate()->begin(), device.device_certificate()->end(), dstatus.device_certificate);
  const char* kDeviceStatus = "SNAPTHREAD_DEVICE_STATUS";
  const Tagger& status_tagger = *device.device_status_tagger();
  if (!Sign(&dstatus, kDeviceStatus, 1, ++seq, status_tagger)) std::abort();
  bytes = Encoded(dstatus);
  ChannelRow("device status", 2, "MAC + own signature sign", "device", bytes.size(),
             [&] { g_sink += Sign(&dstatus, kDeviceStatus, 1, ++seq, status_tagger) ? 1 : 0; });
  PublicKey device_pk{};
  std::copy(std::begin(dstatus.device_public_key), std::end(dstatus.device_public_key), device_pk.begin());
  ChannelRow("device status", 2, "certificate + signature verify", "observer", bytes.size(), [&] {
    g_sink += VerifyDeviceCertificate(server_pk, dstatus.sender_name, dstatus.key_expires, device_pk,
                                      dstatus.device_certificate) &&
                      VerifySignature(bytes.data(), bytes.size(), kDeviceStatus, device_pk)
                  ? 1
                  : 0;
  });
}

std::string LoadAverage() {
  std::ifstream in("/proc/loadavg");
  std::string one, five, fifteen;
  in >> one >> five >> fifteen;
  return one + " " + five + " " + fifteen;
}

}  // namespace

int main(int argc, char** argv) {
  // No options: --help says so (exit 0), anything else is a bad argument (exit 2, docs/cli.md).
  if (argc > 1) {
    const std::string arg = argv[1];
    if (arg == "--help" || arg == "-h") {
      std::printf("snapthread-auth-bench: the median cost of the roles' primitives (docs/security.md); "
                  "takes no arguments\n");
      return 0;
    }
    std::fprintf(stderr, "snapthread-auth-bench: unexpected argument '%s' (it takes none)\n", argv[1]);
    return 2;
  }
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

  ChannelCosts(root);
  std::printf("load average after %s (check %d)\n", LoadAverage().c_str(), g_sink & 1);
  return 0;
}
