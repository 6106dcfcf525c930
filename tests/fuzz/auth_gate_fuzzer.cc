// libFuzzer target: the receive-side authentication gate (common/auth, docs/security.md).
// The input is a script read front to back: a filter set-up, then operations that feed the
// gate genuinely tagged messages (a fixed test device key for MACs and a fixed server
// signing key, so the fuzzer gets past the tag into the freshness logic), the same with
// one byte flipped, tagged for another channel or with another key, messages the server
// signs (statuses, command replies: AdmitSigned), replays of admitted buffers, raw bytes
// as a packet, new epochs, pose echoes for force models and log lines. Each operation
// checks what the gate must do:
//   * a message whose bytes differ from what the key holder tagged is never admitted;
//   * a signed message is admitted only with the server's signature and role;
//   * a buffer admitted once is never admitted again (while the receiver's epoch stays);
//   * the decision equals the one freshness_filter.h specifies (epoch policy, strictly
//     increasing auth_seq), computed here by an independent model;
//   * a force model is admitted only when it echoes a pose that was recorded;
//   * accepted + every refusal reason add up to the messages offered, per reason;
//   * a log line appears only when something was refused since the last one;
//   and ASan/UBSan check that nothing reads out of bounds or overflows.
// Seeds: tests/fuzz/corpus/auth_gate/, written by this binary with
// SNAPTHREAD_FUZZ_WRITE_SEEDS=DIR (see LLVMFuzzerInitialize).
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "auth/freshness_filter.h"
#include "auth/message_gate.h"
#include "auth/message_mac.h"
#include "auth/pose_echo_window.h"
#include "auth/session_key.h"
#include "auth/signature.h"
#include "messages/validate.h"
#include "sample_messages.h"

namespace {

using namespace snapthread;
using auth::Reason;

// ---------------------------------------------------------------- input

// Reads the script front to back; past the end every read gives zeros.
class Script {
 public:
  Script(const uint8_t* data, size_t size) : p_(data), end_(data + size) {}
  bool done() const { return p_ >= end_; }
  uint8_t U8() { return p_ < end_ ? *p_++ : 0; }
  uint16_t U16() { return static_cast<uint16_t>(U8() | (U8() << 8)); }
  int64_t I64() {
    uint64_t v = 0;
    for (int i = 0; i < 8; ++i) v |= static_cast<uint64_t>(U8()) << (8 * i);
    return static_cast<int64_t>(v);
  }
  std::vector<uint8_t> Bytes(size_t n) {
    n = std::min(n, static_cast<size_t>(end_ - p_));
    std::vector<uint8_t> v(p_, p_ + n);
    p_ += n;
    return v;
  }

 private:
  const uint8_t* p_;
  const uint8_t* end_;
};

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

constexpr uint8_t kTestKey[32] = {0x73, 0x6e, 0x61, 0x70, 0x74, 0x68, 0x72, 0x65, 0x61, 0x64, 0x2d,
                                  0x66, 0x75, 0x7a, 0x7a, 0x2d, 0x6b, 0x65, 0x79, 0x2d, 0x30, 0x31,
                                  0x02, 0x03, 0x05, 0x07, 0x0b, 0x0d, 0x11, 0x13, 0x17, 0x1d};
constexpr uint8_t kOtherKey[32] = {0x01};
constexpr char kChannel[] = "FUZZ_GATE";
constexpr char kOtherChannel[] = "FUZZ_GATE2";

const auth::SessionKey& Key() {
  static const auth::SessionKey key = (auth::InitSodium(), auth::SessionKey::FromBytes(kTestKey, 32));
  return key;
}
const auth::SessionKey& OtherKey() {
  static const auth::SessionKey key = (auth::InitSodium(), auth::SessionKey::FromBytes(kOtherKey, 32));
  return key;
}
// The server's signing key (a fixed seed: the test key's bytes).
const auth::Signer& ServerSigner() {
  static const auth::Signer signer = (auth::InitSodium(), auth::Signer::FromSeed(kTestKey));
  return signer;
}

// A device "hand" MACing with `key` (the test key, or another for kWrongKey).
auth::Tagger MacTagger(const auth::SessionKey& key) {
  auth::Tagger t;
  t.role = auth::Role::kDevice;
  t.name = "hand";
  t.mac_key = &key;
  return t;
}

// A few epochs, so scripts hit equal ones often; 0 is "none".
constexpr int64_t kEpochs[] = {0x1111, 0x2222, 0, -5, INT64_MIN, INT64_MAX};

[[noreturn]] void Fail(const char* what) {
  std::fprintf(stderr, "auth_gate_fuzzer: invariant broken: %s\n", what);
  std::abort();
}
#define REQUIRE(cond) \
  do {                \
    if (!(cond)) Fail(#cond); \
  } while (0)

// ---------------------------------------------------------------- the model

// freshness_filter.h's rules, written again from its comments: kFixed takes only its
// (non-zero) epoch, kAdopt any non-zero epoch; auth_seq must be above the last accepted;
// a new epoch from SetEpoch forgets the floor, an adopted one keeps it.
struct FilterModel {
  bool adopt = false;
  int64_t epoch = 0;
  int64_t last_seq = 0;
  uint64_t counts[auth::kReasonCount] = {};

  Reason Check(int64_t e, int64_t s) const {
    if (e == 0 || (!adopt && e != epoch)) return Reason::kForeignEpoch;
    if (s <= last_seq) return Reason::kStaleSequence;
    return Reason::kAccepted;
  }
  void Admit(int64_t e, int64_t s) {
    last_seq = s;
    if (adopt) epoch = e;
  }
  void SetEpoch(int64_t e) {
    if (e != epoch) last_seq = 0;
    epoch = e;
  }
};

struct State {
  explicit State(bool adopt, int64_t epoch)
      : filter("FUZZ_GATE",
               adopt ? auth::FreshnessFilter::EpochPolicy::kAdopt : auth::FreshnessFilter::EpochPolicy::kFixed,
               epoch, /*log_interval_us=*/1000) {
    model.adopt = adopt;
    model.epoch = epoch;
  }
  auth::FreshnessFilter filter;
  FilterModel model;
  auth::PoseEchoWindow poses;
  std::set<std::tuple<int64_t, int64_t, int64_t>> recorded;  // every pose ever recorded
  std::tuple<int64_t, int64_t, int64_t> last_recorded{0, 0, 0};
  bool any_recorded = false;
  std::vector<std::vector<uint8_t>> admitted;  // buffers admitted (bounded), for replays
  // Buffers admitted since the receiver's epoch last changed. SetEpoch forgets the floor
  // (freshness_filter.h), so a buffer may pass again after the epoch went away and came
  // back; the device never does that (its epoch comes from the kAdopt status filter,
  // whose floor spans epochs), so "at most once" is checked per epoch period.
  std::set<std::vector<uint8_t>> admitted_set;
  int64_t now_us = 0;
  uint64_t rejected_at_last_line = 0;
  bool line_taken = false;
};

// After every step: the filter's counters are the model's, per reason, and add up.
void CheckCounters(const State& st) {
  REQUIRE(st.filter.accepted() == st.model.counts[0]);
  uint64_t refused = 0;
  for (int r = 1; r < auth::kReasonCount; ++r) {
    REQUIRE(st.filter.rejected(static_cast<Reason>(r)) == st.model.counts[r]);
    refused += st.model.counts[r];
  }
  REQUIRE(st.filter.rejected() == refused);
  REQUIRE(st.filter.epoch() == st.model.epoch);
  REQUIRE(st.filter.last_accepted_seq() == st.model.last_seq);
}

// ---------------------------------------------------------------- messages

int64_t PickEpoch(Script& in, const State& st) {
  const uint8_t c = in.U8();
  if (c < 128) return st.model.epoch;  // mostly the receiver's own
  if (c < 250) return kEpochs[c % std::size(kEpochs)];
  return in.I64();
}

int64_t PickSeq(Script& in, const State& st) {
  const uint8_t c = in.U8();
  const int64_t last = st.model.last_seq;
  const auto delta = static_cast<int64_t>(in.U8());
  switch (c % 6) {
    case 0:
    case 1: return last < INT64_MAX ? last + 1 : last;
    case 2: return last <= INT64_MAX - 1 - delta ? last + 1 + delta : INT64_MAX;
    case 3: return last;
    case 4: return last >= INT64_MIN + delta ? last - delta : INT64_MIN;
    default: return in.I64();
  }
}

// One of the four types a snapthread receiver admits, with script-chosen fields.
template <class Msg>
Msg Fill(Script& in) {
  Msg m = test_support::Sample<Msg>();
  m.utime = in.I64();
  if constexpr (!std::is_same_v<Msg, command_t>) {
    m.seq = in.I64();
  } else {
    const size_t length = in.U8() % 24;
    m.argument.assign(length, static_cast<char>('a' + in.U8() % 26));
  }
  return m;
}

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

// Counts the gate's decision in the model; an admitted buffer is remembered for replays.
template <class Msg>
Reason Apply(State& st, Reason got, const Msg& decoded, const std::vector<uint8_t>& bytes) {
  ++st.model.counts[static_cast<int>(got)];
  if (got == Reason::kAccepted) {
    st.model.Admit(decoded.epoch, decoded.auth_seq);
    REQUIRE(st.admitted_set.count(bytes) == 0);  // a buffer is admitted at most once
    if (st.admitted.size() < 32) st.admitted.push_back(bytes);
    st.admitted_set.insert(bytes);
  }
  return got;
}

// What a receiver does with a packet on kChannel: exact decode (else dropped before the
// gate, as messages::DecodeAndValidate refuses it), then Admit. *offered says whether the
// gate saw it; the model's expectation is checked and applied.
template <class Msg>
Reason Offer(State& st, const std::vector<uint8_t>& bytes, bool* offered) {
  Msg decoded;
  *offered = messages::DecodeAndValidate(bytes.data(), static_cast<int>(bytes.size()), &decoded, nullptr);
  if (!*offered) {
    // Never handed to the gate; the tag checks must still be safe on any bytes.
    (void)auth::VerifyMac(bytes.data(), bytes.size(), kChannel, Key());
    (void)auth::VerifySignature(bytes.data(), bytes.size(), kChannel, ServerSigner().public_key());
    return Reason::kBadMac;
  }
  const bool mac_ok = auth::VerifyMac(bytes.data(), bytes.size(), kChannel, Key());
  const Reason expected = mac_ok ? st.model.Check(decoded.epoch, decoded.auth_seq) : Reason::kBadMac;
  const Reason got = auth::Admit(bytes.data(), bytes.size(), decoded, kChannel, Key(), &st.filter);
  REQUIRE(got == expected);
  return Apply(st, got, decoded, bytes);
}

// What the observers, the devices and snapthread-ctl do with a message the server signs:
// exact decode, then AdmitSigned (the server's role and signature, then freshness).
template <class Msg>
Reason OfferSigned(State& st, const std::vector<uint8_t>& bytes, bool* offered) {
  Msg decoded;
  *offered = messages::DecodeAndValidate(bytes.data(), static_cast<int>(bytes.size()), &decoded, nullptr);
  if (!*offered) return Reason::kBadMac;
  const bool sig_ok = decoded.sender_role == static_cast<int8_t>(auth::Role::kServer) &&
                      auth::VerifySignature(bytes.data(), bytes.size(), kChannel, ServerSigner().public_key());
  const Reason expected = sig_ok ? st.model.Check(decoded.epoch, decoded.auth_seq) : Reason::kBadMac;
  const Reason got =
      auth::AdmitSigned(bytes.data(), bytes.size(), decoded, kChannel, ServerSigner().public_key(), &st.filter);
  REQUIRE(got == expected);
  return Apply(st, got, decoded, bytes);
}

using OfferFn = Reason (*)(State&, const std::vector<uint8_t>&, bool*);

// Signs a script-chosen message of a script-chosen type.
bool MakeSigned(Script& in, State& st, const char* channel, const auth::SessionKey& key, Signed* out, OfferFn* offer) {
  const int64_t epoch = PickEpoch(in, st);
  const int64_t seq = PickSeq(in, st);
  switch (in.U8() % 5) {
    case 0: {
      auto m = Fill<device_state_t>(in);
      *offer = &Offer<device_state_t>;
      return SignInto(&m, channel, key, epoch, seq, out);
    }
    case 1: {
      auto m = Fill<solver_status_t>(in);
      *offer = &Offer<solver_status_t>;
      return SignInto(&m, channel, key, epoch, seq, out);
    }
    case 2: {
      auto m = Fill<command_t>(in);
      *offer = &Offer<command_t>;
      return SignInto(&m, channel, key, epoch, seq, out);
    }
    case 3: {
      auto m = Fill<force_model_t>(in);
      *offer = &Offer<force_model_t>;
      return SignInto(&m, channel, key, epoch, seq, out);
    }
    default: {
      auto m = Fill<command_reply_t>(in);
      *offer = &Offer<command_reply_t>;
      return SignInto(&m, channel, key, epoch, seq, out);
    }
  }
}

// A status or a command reply tagged by the server's signer, or by a tagger claiming
// another role or holding no signer; sometimes one byte flipped where the signature
// covers it (outside signature2 and mac). Offered through AdmitSigned.
void ServerSignedStep(Script& in, State& st) {
  const int64_t epoch = PickEpoch(in, st);
  const int64_t seq = PickSeq(in, st);
  const uint8_t how = in.U8();
  auth::Tagger tagger;
  tagger.role = how % 8 == 1 ? auth::Role::kOperator : auth::Role::kServer;  // claims another role
  tagger.signer = how % 8 == 2 ? nullptr : &ServerSigner();                   // 2: unsigned
  if (how % 8 == 3) tagger.mac_key = &Key();                                  // a MAC instead
  if (how % 8 == 3) tagger.signer = nullptr;
  const bool reply = (how & 0x80) != 0;
  Signed s;
  OfferFn offer = nullptr;
  if (reply) {
    auto m = Fill<command_reply_t>(in);
    offer = &OfferSigned<command_reply_t>;
    if (!SignInto(&m, kChannel, tagger, epoch, seq, &s)) return;
  } else {
    auto m = Fill<solver_status_t>(in);
    offer = &OfferSigned<solver_status_t>;
    if (!SignInto(&m, kChannel, tagger, epoch, seq, &s)) return;
  }
  const bool flipped = (how & 0x40) != 0;
  if (flipped) {
    const size_t covered = s.bytes.size() - auth::kSignatureBytes - auth::kMacBytes;
    s.bytes[in.U16() % covered] ^= static_cast<uint8_t>(1u + in.U8() % 255u);
  }
  bool offered = false;
  const Reason got = offer(st, s.bytes, &offered);
  if (how % 8 >= 1 && how % 8 <= 3) REQUIRE(got != Reason::kAccepted);  // not the server signing as itself
  if (flipped) {
    REQUIRE(!auth::VerifySignature(s.bytes.data(), s.bytes.size(), kChannel, ServerSigner().public_key()));
    REQUIRE(got != Reason::kAccepted);
  }
}

// ---------------------------------------------------------------- force models

void ForceModelStep(Script& in, State& st) {
  force_model_t m = Fill<force_model_t>(in);
  // Echo the last recorded pose, an older one, or anything.
  const uint8_t how = in.U8() % 3;
  if (how == 0 && st.any_recorded) {
    std::tie(m.epoch, m.device_seq, m.device_utime) = st.last_recorded;
  } else if (how == 1 && !st.recorded.empty()) {
    auto it = st.recorded.begin();
    std::advance(it, in.U16() % st.recorded.size());
    std::tie(m.epoch, m.device_seq, m.device_utime) = *it;
  } else {
    m.device_seq = in.I64();
    m.device_utime = in.I64();
  }
  const int64_t epoch = in.U8() < 200 ? m.epoch : PickEpoch(in, st);
  const int64_t seq = PickSeq(in, st);
  const uint8_t flip = in.U8();
  Signed s;
  if (!SignInto(&m, kChannel, Key(), epoch, seq, &s)) return;
  if (flip >= 224) s.bytes[in.U16() % s.bytes.size()] ^= static_cast<uint8_t>(1u + in.U8() % 255u);
  force_model_t decoded;
  if (!messages::DecodeAndValidate(s.bytes.data(), static_cast<int>(s.bytes.size()), &decoded, nullptr)) return;
  const bool mac_ok = auth::VerifyMac(s.bytes.data(), s.bytes.size(), kChannel, Key());
  const bool echoed = st.poses.Contains(decoded.epoch, decoded.device_seq, decoded.device_utime);
  // No false echo: the window only knows poses that were recorded.
  if (echoed) REQUIRE(st.recorded.count({decoded.epoch, decoded.device_seq, decoded.device_utime}) == 1);
  Reason expected = mac_ok ? st.model.Check(decoded.epoch, decoded.auth_seq) : Reason::kBadMac;
  if (expected == Reason::kAccepted && !echoed) expected = Reason::kUnsentPoseEcho;
  const Reason got =
      auth::AdmitForceModel(s.bytes.data(), s.bytes.size(), decoded, kChannel, Key(), st.poses, &st.filter);
  REQUIRE(got == expected);
  if (flip >= 224 && s.bytes != test_support::Encode(m)) {
    REQUIRE(!mac_ok);
    REQUIRE(got != Reason::kAccepted);
  }
  ++st.model.counts[static_cast<int>(got)];
  if (got == Reason::kAccepted) {
    st.model.Admit(decoded.epoch, decoded.auth_seq);
    REQUIRE(st.admitted_set.count(s.bytes) == 0);
    st.admitted_set.insert(s.bytes);
    if (st.admitted.size() < 32) st.admitted.push_back(s.bytes);
  }
}

// ---------------------------------------------------------------- one step

void Step(Script& in, State& st) {
  const uint8_t op = in.U8() % kOpCount;
  switch (op) {
    case kGenuine:
    case kFlipped:
    case kWrongChannel:
    case kWrongKey: {
      const char* channel = op == kWrongChannel ? kOtherChannel : kChannel;
      const auth::SessionKey& key = op == kWrongKey ? OtherKey() : Key();
      Signed s;
      OfferFn offer = nullptr;
      if (!MakeSigned(in, st, channel, key, &s, &offer)) return;
      const std::vector<uint8_t> original = s.bytes;
      if (op == kFlipped) {
        const size_t at = in.U16() % s.bytes.size();
        s.bytes[at] ^= static_cast<uint8_t>(1u + in.U8() % 255u);
      }
      bool offered = false;
      const Reason got = offer(st, s.bytes, &offered);
      if (op != kGenuine) {
        // Any byte changed, another channel or another key: refused by the MAC.
        REQUIRE(!auth::VerifyMac(s.bytes.data(), s.bytes.size(), kChannel, Key()));
        if (offered) REQUIRE(got == Reason::kBadMac);
      } else {
        REQUIRE(offered);  // a signed sample always decodes
        // Offered again at once: never a second time.
        bool again = false;
        REQUIRE(offer(st, original, &again) != Reason::kAccepted);
      }
      break;
    }
    case kReplay: {
      if (st.admitted.empty()) return;
      const std::vector<uint8_t> bytes = st.admitted[in.U8() % st.admitted.size()];
      const bool once = st.admitted_set.count(bytes) == 1;
      bool offered = false;
      Reason got = Offer<device_state_t>(st, bytes, &offered);
      if (!offered) got = Offer<solver_status_t>(st, bytes, &offered);
      if (!offered) got = Offer<command_t>(st, bytes, &offered);
      if (!offered) got = Offer<force_model_t>(st, bytes, &offered);
      if (!offered) got = Offer<command_reply_t>(st, bytes, &offered);
      REQUIRE(offered);
      if (once) REQUIRE(got != Reason::kAccepted);
      break;
    }
    case kRaw: {
      // Arbitrary bytes (a corpus entry may hold a genuinely signed message, then the
      // freshness rules decide; otherwise the MAC refuses it).
      const uint8_t type = in.U8();
      const std::vector<uint8_t> bytes = in.Bytes(in.U16() % 4096);
      bool offered = false;
      switch (type % 7) {
        case 0: Offer<device_state_t>(st, bytes, &offered); break;
        case 1: Offer<solver_status_t>(st, bytes, &offered); break;
        case 2: Offer<command_t>(st, bytes, &offered); break;
        case 3: Offer<force_model_t>(st, bytes, &offered); break;
        case 4: Offer<command_reply_t>(st, bytes, &offered); break;
        case 5: OfferSigned<solver_status_t>(st, bytes, &offered); break;
        default: OfferSigned<command_reply_t>(st, bytes, &offered); break;
      }
      break;
    }
    case kSetEpoch: {
      const int64_t e = PickEpoch(in, st);
      if (e != st.model.epoch) st.admitted_set.clear();
      st.filter.SetEpoch(e);
      st.model.SetEpoch(e);
      break;
    }
    case kRecordPose: {
      const int64_t e = in.U8() < 200 ? st.model.epoch : PickEpoch(in, st);
      const auto seq = std::get<1>(st.last_recorded) + 1 + static_cast<int64_t>(in.U8() % 4 == 0 ? in.U16() : 0);
      const int64_t utime = in.I64();
      st.poses.Record(e, seq, utime);
      st.recorded.insert({e, seq, utime});
      st.last_recorded = {e, seq, utime};
      st.any_recorded = true;
      // The pose just sent is in the window.
      REQUIRE(st.poses.Contains(e, seq, utime));
      break;
    }
    case kForceModel: ForceModelStep(in, st); break;
    case kServerSigned: ServerSignedStep(in, st); break;
    case kLogLine: {
      st.now_us += in.U16();
      std::string line;
      const bool took = st.filter.TakeLogLine(st.now_us, &line);
      if (took) {
        REQUIRE(line.rfind("FUZZ_GATE: ", 0) == 0);
        REQUIRE(st.filter.rejected() > st.rejected_at_last_line);
        st.rejected_at_last_line = st.filter.rejected();
        st.line_taken = true;
      } else if (!st.line_taken) {
        REQUIRE(st.filter.rejected() == 0);  // the first refusal is reported at once
      }
      break;
    }
    default: break;
  }
}

// ---------------------------------------------------------------- seeds

// Scripts that reach every operation, some of them with genuinely signed packets as raw
// bytes (so mutations start past the MAC).
void WriteSeeds(const std::string& dir) {
  auto write = [&](const char* name, const std::vector<uint8_t>& bytes) {
    std::ofstream(dir + "/" + name, std::ios::binary)
        .write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  };
  auto le64 = [](std::vector<uint8_t>* v, int64_t x) {
    for (int i = 0; i < 8; ++i) v->push_back(static_cast<uint8_t>(static_cast<uint64_t>(x) >> (8 * i)));
  };
  // Header: policy byte (even: kFixed), epoch choice byte (0: kEpochs[0]).
  // Genuine: op, epoch choice (<128: own), seq choice, delta, type, utime(8), seq(8)[, command bytes].
  std::vector<uint8_t> genuine = {0, 0};
  for (int type = 0; type < 4; ++type)
    for (int k = 0; k < 3; ++k) {
      genuine.insert(genuine.end(), {kGenuine, 0, 0, 0, static_cast<uint8_t>(type)});
      le64(&genuine, 1700000000000000 + k);
      if (type == 2) {
        genuine.insert(genuine.end(), {5, 3});  // command_t: argument length, letter
      } else {
        le64(&genuine, k);  // seq
      }
      genuine.insert(genuine.end(), {kReplay, static_cast<uint8_t>(k)});
    }
  genuine.insert(genuine.end(), {kLogLine, 0x10, 0x27});
  write("genuine_and_replays", genuine);

  std::vector<uint8_t> flips = {1, 0};  // kAdopt
  for (int k = 0; k < 8; ++k) {
    flips.insert(flips.end(), {kFlipped, 0, 2, 7, static_cast<uint8_t>(k % 4)});
    le64(&flips, 99);
    if (k % 4 == 2) {
      flips.insert(flips.end(), {5, 3});
    } else {
      le64(&flips, k);
    }
    flips.insert(flips.end(), {static_cast<uint8_t>(17 * k), 0, 1});
    flips.insert(flips.end(), {kWrongKey, 0, 0, 0, 0});
    le64(&flips, 1);
    le64(&flips, 2);
    flips.insert(flips.end(), {kWrongChannel, 0, 0, 0, 1});
    le64(&flips, 1);
    le64(&flips, 2);
  }
  write("flips_keys_channels", flips);

  std::vector<uint8_t> models = {0, 0};
  for (int k = 0; k < 6; ++k) {
    // A pose (own epoch, next seq, utime), a model echoing it, a model echoing nothing
    // with one byte flipped.
    models.insert(models.end(), {kRecordPose, 0, 1});
    le64(&models, 1000 * k);
    models.insert(models.end(), {kForceModel});
    le64(&models, 5);
    le64(&models, k);
    models.insert(models.end(), {0, 0, 0, 0, 0});
    models.insert(models.end(), {kForceModel});
    le64(&models, 5);
    le64(&models, k);
    models.push_back(2);
    le64(&models, 77 + k);
    le64(&models, 1000 * k);
    models.insert(models.end(), {0, 0, 0, 230, 40, 0, 9});
  }
  models.insert(models.end(), {kSetEpoch, 130, kLogLine, 0xff, 0xff});
  write("force_models_and_echoes", models);

  // Raw: genuinely signed packets of each type as bytes (header kFixed at kEpochs[0]).
  std::vector<uint8_t> raw = {0, 0};
  int64_t seq = 1;
  auto add_raw = [&](uint8_t type, std::vector<uint8_t> bytes) {
    const auto size_lo = static_cast<uint8_t>(bytes.size() & 0xff);
    const auto size_hi = static_cast<uint8_t>(bytes.size() >> 8);
    raw.insert(raw.end(), {kRaw, type, size_lo, size_hi});
    raw.insert(raw.end(), bytes.begin(), bytes.end());
  };
  {
    auto m = test_support::Sample<device_state_t>();
    Signed s;
    if (SignInto(&m, kChannel, Key(), kEpochs[0], seq++, &s)) add_raw(0, s.bytes);
  }
  {
    auto m = test_support::Sample<solver_status_t>();
    Signed s;
    if (SignInto(&m, kChannel, Key(), kEpochs[0], seq++, &s)) add_raw(1, s.bytes);
  }
  {
    auto m = test_support::Sample<command_t>();
    Signed s;
    if (SignInto(&m, kChannel, Key(), kEpochs[0], seq++, &s)) add_raw(2, s.bytes);
  }
  {
    auto m = test_support::Sample<force_model_t>();
    Signed s;
    if (SignInto(&m, kChannel, Key(), kEpochs[0], seq++, &s)) add_raw(3, s.bytes);
  }
  {
    auto m = test_support::Sample<command_reply_t>();
    Signed s;
    if (SignInto(&m, kChannel, Key(), kEpochs[0], seq++, &s)) add_raw(4, s.bytes);
  }
  // What the server signs: a status and a reply.
  auth::Tagger server;
  server.signer = &ServerSigner();
  {
    auto m = test_support::Sample<solver_status_t>();
    Signed s;
    if (SignInto(&m, kChannel, server, kEpochs[0], seq++, &s)) add_raw(5, s.bytes);
  }
  {
    auto m = test_support::Sample<command_reply_t>();
    Signed s;
    if (SignInto(&m, kChannel, server, kEpochs[0], seq++, &s)) add_raw(6, s.bytes);
  }
  raw.insert(raw.end(), {kReplay, 0, kReplay, 1, kLogLine, 1, 0});
  write("raw_signed_packets", raw);

  // Server-signed steps: own epoch, next seq, each way of tagging, flipped or not, status
  // or reply: how, then utime(8), seq(8), flip position(2), xor.
  std::vector<uint8_t> signed_steps = {1, 0};  // kAdopt
  for (int k = 0; k < 16; ++k) {
    const auto how = static_cast<uint8_t>((k % 4) | (k & 4 ? 0x40 : 0) | (k & 8 ? 0x80 : 0));
    signed_steps.insert(signed_steps.end(), {kServerSigned, 0, 0, 0, how});
    le64(&signed_steps, 1700000000000000 + k);
    le64(&signed_steps, k);
    signed_steps.insert(signed_steps.end(), {static_cast<uint8_t>(13 * k), 0, 1});
  }
  write("server_signed", signed_steps);
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  if (const char* dir = std::getenv("SNAPTHREAD_FUZZ_WRITE_SEEDS"); dir != nullptr && *dir != '\0') {
    WriteSeeds(dir);
    std::exit(0);
  }
  (void)Key();
  (void)OtherKey();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  Script in(data, size);
  const bool adopt = (in.U8() & 1) != 0;
  const uint8_t e = in.U8();
  State st(adopt, e < 250 ? kEpochs[e % std::size(kEpochs)] : in.I64());
  // PoseEchoWindow is 2048 slots of atomics (~80 kB): fine per input.
  for (int steps = 0; steps < 256 && !in.done(); ++steps) {
    Step(in, st);
    CheckCounters(st);
  }
  // SNAPTHREAD_FUZZ_VERBOSE=1: what the input reached (to check that seeds get past the MAC).
  static const bool verbose = std::getenv("SNAPTHREAD_FUZZ_VERBOSE") != nullptr;
  if (verbose) {
    std::fprintf(stderr, "auth_gate_fuzzer: accepted %llu", static_cast<unsigned long long>(st.filter.accepted()));
    for (int r = 1; r < auth::kReasonCount; ++r)
      std::fprintf(stderr, ", %s %llu", auth::ReasonName(static_cast<Reason>(r)),
                   static_cast<unsigned long long>(st.filter.rejected(static_cast<Reason>(r))));
    std::fprintf(stderr, "\n");
  }
  return 0;
}
