// What auth_gate_fuzzer.cc and the seeds it writes (auth_gate_seeds.cc) share: the script's
// operation codes, the fixed test keys and channels, and signing a message into bytes.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "auth/message_mac.h"
#include "auth/session_key.h"
#include "auth/signature.h"
#include "sample_messages.h"

namespace snapthread::fuzz_gate {

// Operation codes (the first byte of each step, modulo kOpCount).
enum Op : uint8_t {
  kGenuine = 0,      // sign a message with the test key, offer it
  kFlipped,          // sign, flip one byte, offer it
  kWrongChannel,     // signed for another channel
  kWrongKey,         // signed with another key
  kReplay,           // offer an already admitted buffer again
  kRaw,              // arbitrary bytes as a packet
  kSetEpoch,         // the receiver's epoch changes
  kRecordPose,       // the device sends a pose (PoseEchoWindow)
  kForceModel,       // a signed force model through AdmitForceModel
  kLogLine,          // TakeLogLine
  kServerSigned,     // a status or reply signed by the server (or claiming another role), maybe flipped
  kOpCount
};

// ---------------------------------------------------------------- keys and channels

inline constexpr uint8_t kTestKey[32] = {0x73, 0x6e, 0x61, 0x70, 0x74, 0x68, 0x72, 0x65, 0x61, 0x64, 0x2d,
                                  0x66, 0x75, 0x7a, 0x7a, 0x2d, 0x6b, 0x65, 0x79, 0x2d, 0x30, 0x31,
                                  0x02, 0x03, 0x05, 0x07, 0x0b, 0x0d, 0x11, 0x13, 0x17, 0x1d};
inline constexpr uint8_t kOtherKey[32] = {0x01};
inline constexpr char kChannel[] = "FUZZ_GATE";
inline constexpr char kOtherChannel[] = "FUZZ_GATE2";

inline const auth::SessionKey& Key() {
  static const auth::SessionKey key = (auth::InitSodium(), auth::SessionKey::FromBytes(kTestKey, 32));
  return key;
}
inline const auth::SessionKey& OtherKey() {
  static const auth::SessionKey key = (auth::InitSodium(), auth::SessionKey::FromBytes(kOtherKey, 32));
  return key;
}
// The server's signing key (a fixed seed: the test key's bytes).
inline const auth::Signer& ServerSigner() {
  static const auth::Signer signer = (auth::InitSodium(), auth::Signer::FromSeed(kTestKey));
  return signer;
}

// A device "hand" MACing with `key` (the test key, or another for kWrongKey).
inline auth::Tagger MacTagger(const auth::SessionKey& key) {
  auth::Tagger t;
  t.role = auth::Role::kDevice;
  t.name = "hand";
  t.mac_key = &key;
  return t;
}

// A few epochs, so scripts hit equal ones often; 0 is "none".
inline constexpr int64_t kEpochs[] = {0x1111, 0x2222, 0, -5, INT64_MIN, INT64_MAX};

// ---------------------------------------------------------------- signing

struct Signed {
  std::vector<uint8_t> bytes;
  int64_t epoch = 0, seq = 0;
};

template <class Msg>
bool SignInto(Msg* m, const char* channel, const auth::Tagger& tagger, int64_t epoch, int64_t seq, Signed* out) {
  if (!auth::Sign(m, channel, epoch, seq, tagger)) return false;
  out->bytes = test_support::Encode(*m);
  out->epoch = epoch;
  out->seq = seq;
  return true;
}
template <class Msg>
bool SignInto(Msg* m, const char* channel, const auth::SessionKey& key, int64_t epoch, int64_t seq, Signed* out) {
  if (!auth::Sign(m, channel, epoch, seq, MacTagger(key))) return false;
  out->bytes = test_support::Encode(*m);
  out->epoch = epoch;
  out->seq = seq;
  return true;
}

// Scripts that reach every operation, written to `dir` (SNAPTHREAD_FUZZ_WRITE_SEEDS).
void WriteSeeds(const std::string& dir);

}  // namespace snapthread::fuzz_gate
