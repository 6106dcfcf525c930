// Writes one valid encoding of every message type, prefixed by message_fuzzer's type byte,
// into DIR: the message seed corpus (tests/fuzz/corpus/messages/ holds a committed copy;
// deploy/test.sh regenerates it so the seeds follow the .lcm types).
// Usage: message_seeds DIR
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "messages/validate.h"
#include "sample_messages.h"

namespace {

using namespace snapthread;

template <class T>
bool Write(const std::string& dir, int type_byte, const char* name, const T& msg) {
  std::string why;
  if (!messages::Validate(msg, &why)) {
    std::fprintf(stderr, "message_seeds: %s seed is invalid: %s\n", name, why.c_str());
    return false;
  }
  std::vector<char> buf(1 + msg.getEncodedSize());
  buf[0] = static_cast<char>(type_byte);
  msg.encode(buf.data() + 1, 0, static_cast<int>(buf.size() - 1));
  std::ofstream(dir + "/" + name + ".bin", std::ios::binary).write(buf.data(), static_cast<std::streamsize>(buf.size()));
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: message_seeds DIR\n");
    return 2;
  }
  const std::string dir = argv[1];
  // The samples fill every field (tests/support/sample_messages.h), so the fuzzer starts
  // from messages that reach every row of every field table.
  using snapthread::test_support::Sample;
  const bool ok = Write(dir, 0, "device_state", Sample<device_state_t>()) &&
                  Write(dir, 1, "force_model", Sample<force_model_t>()) &&
                  Write(dir, 2, "thread_shape", Sample<thread_shape_t>()) &&
                  Write(dir, 3, "solver_status", Sample<solver_status_t>()) &&
                  Write(dir, 4, "device_status", Sample<device_status_t>()) &&
                  Write(dir, 5, "command", Sample<command_t>()) &&
                  Write(dir, 6, "command_reply", Sample<command_reply_t>());
  return ok ? 0 : 1;
}
