// One filled-in message of each snapthread LCM type, for the auth tests.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "snapthread/command_t.hpp"
#include "snapthread/device_state_t.hpp"
#include "snapthread/device_status_t.hpp"
#include "snapthread/force_model_t.hpp"
#include "snapthread/solver_status_t.hpp"
#include "snapthread/thread_shape_t.hpp"

namespace snapthread::auth::testing {

inline device_state_t Sample(const device_state_t*) {
  device_state_t m{};
  m.utime = 123456789;
  m.seq = 42;
  m.device_id = "virtual-hand";
  m.position[0] = 0.01;
  m.position[1] = -0.02;
  m.position[2] = 0.03;
  m.orientation[0] = 1.0;
  m.buttons = 1;
  return m;
}

inline force_model_t Sample(const force_model_t*) {
  force_model_t m{};
  m.utime = 1700000000000000;
  m.seq = 7;
  m.device_seq = 41;
  m.device_utime = 123456000;
  m.server_receive_utime = 1700000000000100;
  m.solve_us = 250;
  m.status = force_model_t::STATUS_NEAR_FOLD;
  for (int i = 0; i < 3; ++i) {
    m.u0[i] = 0.01 * (i + 1);
    m.f0[i] = -0.5 * (i + 1);
    m.torque0[i] = 0.001 * i;
    for (int j = 0; j < 3; ++j) m.K[i][j] = (i == j) ? -300.0 : 10.0 * (i + j);
  }
  m.has_torque = 1;
  m.iterations = 3;
  m.residual = 1e-9;
  return m;
}

inline thread_shape_t Sample(const thread_shape_t*, int nodes = 12) {
  thread_shape_t m{};
  m.utime = 1700000000000000;
  m.seq = 3;
  m.scene = "thread3d_loop";
  m.model = "thread3d";
  m.num_nodes = nodes;
  m.positions.assign(static_cast<size_t>(nodes), std::vector<double>(3, 0.0));
  for (int i = 0; i < nodes; ++i) m.positions[static_cast<size_t>(i)][0] = 0.1 * i;
  m.grasp[0] = 1.0;
  m.force_newtons[2] = 0.25;
  m.status = 1;
  m.snaps = 2;
  return m;
}

inline solver_status_t Sample(const solver_status_t*) {
  solver_status_t m{};
  m.utime = 1700000000000000;
  m.seq = 11;
  m.scene = "zeeman";
  m.method = "higher-order";
  m.iterations = 4;
  m.residual = 1e-10;
  m.lambda_min = 0.3;
  m.update_rate_hz = 998.0;
  m.updates = 1000;
  m.rejected_messages = 5;
  return m;
}

inline device_status_t Sample(const device_status_t*) {
  device_status_t m{};
  m.utime = 99;
  m.seq = 5;
  m.device_id = "virtual-hand";
  m.tick_rate_hz = 1000.0;
  m.ticks = 12345;
  m.models_received = 1200;
  m.models_rejected = 3;
  return m;
}

inline command_t Sample(const command_t*) {
  command_t m{};
  m.utime = 77;
  m.command = command_t::SET_METHOD;
  m.argument = "newton-ls";
  return m;
}

template <class Msg>
Msg Sample() {
  return Sample(static_cast<const Msg*>(nullptr));
}

template <class Msg>
std::vector<uint8_t> Encode(const Msg& m) {
  std::vector<uint8_t> buf(static_cast<size_t>(m.getEncodedSize()));
  m.encode(buf.data(), 0, static_cast<int>(buf.size()));
  return buf;
}

}  // namespace snapthread::auth::testing
