// Writes one valid encoding of every message type, prefixed by message_fuzzer's type byte,
// into DIR: the message seed corpus (tests/fuzz/corpus/messages/ holds a committed copy;
// deploy/test.sh regenerates it so the seeds follow the .lcm types).
// Usage: message_seeds DIR
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "messages/validate.h"

namespace {

using namespace snapthread;

template <class T>
bool Write(const std::string& dir, int type_byte, const char* name, const T& msg) {
  std::string why;
  if (!transport::Validate(msg, &why)) {
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
  device_state_t ds{};
  ds.utime = 1000;
  ds.seq = 7;
  ds.device_id = "sim-path";
  ds.position[0] = 0.01;
  ds.orientation[0] = 1.0;
  force_model_t fm{};
  fm.seq = 3;
  fm.device_seq = 7;
  fm.f0[1] = 0.5;
  for (int i = 0; i < 3; ++i) fm.K[i][i] = -100.0;
  thread_shape_t sh{};
  sh.scene = "curve2d_snap";
  sh.model = "curve2d";
  sh.num_nodes = 3;
  sh.positions = {{0, 0, 0}, {1, 0, 0}, {2, 0.5, 0}};
  solver_status_t st{};
  st.scene = "curve2d_snap";
  st.method = "higher-order";
  device_status_t dst{};
  dst.device_id = "sim-path";
  command_t cmd{};
  cmd.command = command_t::SET_METHOD;
  cmd.argument = "newton-ls";
  const bool ok = Write(dir, 0, "device_state", ds) && Write(dir, 1, "force_model", fm) &&
                  Write(dir, 2, "thread_shape", sh) && Write(dir, 3, "solver_status", st) &&
                  Write(dir, 4, "device_status", dst) && Write(dir, 5, "command", cmd);
  return ok ? 0 : 1;
}
