// The seeds of auth_gate_fuzzer (tests/fuzz/corpus/auth_gate/): scripts that reach every
// operation, some of them with genuinely tagged packets as raw bytes (so mutations start
// past the tags).
#include <fstream>
#include <string>
#include <vector>

#include "auth_gate_fuzzer.h"

namespace snapthread::fuzz_gate {

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

}  // namespace snapthread::fuzz_gate
