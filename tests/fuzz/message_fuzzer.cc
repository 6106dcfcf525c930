// libFuzzer target: every message decoder + validator. The first byte picks the type, the
// rest is the packet as it would arrive on the wire. DecodeAndValidate must never throw or
// read out of bounds (ASan), and a message it accepts must encode back to the same bytes.
// Seed corpus: tests/fuzz/corpus/messages/ (one valid encoding per type, made by
// message_fuzzer itself with SNAPTHREAD_FUZZ_WRITE_SEEDS=DIR).
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include "messages/validate.h"

namespace {

using namespace snapthread;

template <class T>
void Check(const uint8_t* data, size_t size) {
  T msg;
  std::string why;
  if (!messages::DecodeAndValidate(data, static_cast<int>(size), &msg, &why)) {
    if (why.empty()) std::abort();  // a rejection always names its reason
    return;
  }
  std::vector<uint8_t> again(msg.getEncodedSize());
  if (msg.encode(again.data(), 0, static_cast<int>(again.size())) != static_cast<int>(size) ||
      std::memcmp(again.data(), data, size) != 0) {
    std::abort();  // accepted bytes must be exactly one message
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  const uint8_t* body = data + 1;
  const size_t n = size - 1;
  switch (data[0] % 7) {
    case 0: Check<device_state_t>(body, n); break;
    case 1: Check<force_model_t>(body, n); break;
    case 2: Check<thread_shape_t>(body, n); break;
    case 3: Check<solver_status_t>(body, n); break;
    case 4: Check<device_status_t>(body, n); break;
    case 5: Check<command_t>(body, n); break;
    default: Check<command_reply_t>(body, n); break;
  }
  return 0;
}
