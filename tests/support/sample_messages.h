// One filled-in message of each snapthread LCM type (every field set, each to a valid
// value), for the transport round trips, validation and the auth tests.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "snapthread/command_reply_t.hpp"
#include "snapthread/command_t.hpp"
#include "snapthread/device_state_t.hpp"
#include "snapthread/device_status_t.hpp"
#include "snapthread/force_model_t.hpp"
#include "snapthread/solver_status_t.hpp"
#include "snapthread/thread_shape_t.hpp"

namespace snapthread::test_support {

// Designated initializers name every field: with -Wextra (missing-field-initializers) a
// field added to a type fails the build here until its sample sets it. The samples are
// unsigned (the authentication trailer zero).

inline device_state_t Sample(const device_state_t*) {
  return {.utime = 123456789, .seq = 42, .device_id = "virtual-hand",
          .position = {0.01, -0.02, 0.03}, .orientation = {1.0, 0.0, 0.0, 0.0}, .buttons = 1,
          .grasp = "", .snap_fold_id = 3,
          .epoch = 0, .auth_seq = 0, .sender_role = 0, .sender_name = "", .key_expires = 0,
          .key_id = 0, .signature = {}, .signature2 = {}, .mac = {}};
}

inline force_model_t Sample(const force_model_t*) {
  return {.utime = 1700000000000000, .seq = 7, .device_seq = 41, .device_utime = 123456000,
          .server_receive_utime = 1700000000000100, .solve_us = 250,
          .status = force_model_t::STATUS_NEAR_FOLD, .u0 = {0.01, 0.02, 0.03},
          .f0 = {-0.5, -1.0, -1.5}, .K = {{-300.0, 10.0, 20.0}, {10.0, -300.0, 30.0},
                                          {20.0, 30.0, -300.0}},
          .has_torque = 1, .torque0 = {0.0, 0.001, 0.002}, .iterations = 3, .residual = 1e-9,
          .has_wrench = 1, .q0 = {1.0, 0.0, 0.0, 0.0},
          .K6 = {{-300.0, 0, 0, 0, 0, 0}, {0, -300.0, 0, 0, 0, 0}, {0, 0, -300.0, 0, 0, 0},
                 {0, 0, 0, -0.5, 0, 0}, {0, 0, 0, 0, -0.5, 0}, {0, 0, 0, 0, 0, -0.5}},
          .grasp = "", .has_fold = 1, .fold_id = 5, .fold_point = {0.02, 0.0, 0.0},
          .fold_normal = {0.6, 0.0, 0.0}, .fold_curvature = 0.5, .post_u0 = {0.02, 0.0, 0.0},
          .post_f0 = {0.5, 0.0, 0.0}, .post_K = {{-100.0, 0, 0}, {0, -100.0, 0}, {0, 0, -100.0}},
          .fold_q = {0.9950041652780258, 0.0, 0.0, 0.09983341664682815}, .fold_normal_r = {0.0, 0.0, 0.8},
          .post_torque0 = {0.0, -0.001, 0.002},
          .force_error_n = 2.5e-4,
          .epoch = 0, .auth_seq = 0, .sender_role = 0, .sender_name = "", .key_expires = 0,
          .key_id = 0, .signature = {}, .signature2 = {}, .mac = {}};
}

// A shape of `nodes` nodes along a line.
inline thread_shape_t SampleShape(int nodes) {
  std::vector<std::vector<double>> positions;
  for (int i = 0; i < nodes; ++i) positions.push_back({1.0 * i, 0.5 * i, 0.0});
  return {.utime = 5, .seq = 6, .scene = "curve2d_snap", .model = "curve2d", .num_nodes = nodes,
          .positions = std::move(positions), .grasp = {1.0 * nodes, 0.0, 0.0},
          .grip_direction = {1.0, 0.0, 0.0}, .force = {0.0, 2.0, 0.0},
          .force_newtons = {0.0, 0.2, 0.0}, .status = force_model_t::STATUS_SNAPPED, .snaps = 3,
          .num_frames = 1,
          .frames = {{0.0, 1.0, 0.0, 0.25}}, .grasp_names = "left,right", .num_grasps = 2,
          .grasps = {{0.0, 0.0, 0.0, -1.0, 0.0, 0.0}, {1.0 * nodes, 0.0, 0.0, 1.0, 0.0, 0.0}},
          .num_contacts = 1, .contacts = {{1.0, 0.5, 0.0, 1.0, 0.5, 0.1}}, .knot = "unknot",
          .epoch = 0, .auth_seq = 0, .sender_role = 0, .sender_name = "", .key_expires = 0,
          .key_id = 0, .signature = {}, .signature2 = {}, .mac = {}};
}

inline thread_shape_t Sample(const thread_shape_t*) { return SampleShape(12); }

inline solver_status_t Sample(const solver_status_t*) {
  return {.utime = 9, .seq = 10, .scene = "zeeman", .method = "higher-order", .iterations = 2,
          .residual = 1e-11, .lambda_min = -0.25, .negative_pivots = 1,
          .status = force_model_t::STATUS_REGULAR, .update_rate_hz = 950.0,
          .solve_us_p50 = 40.0, .solve_us_p99 = 120.0, .updates = 1000, .snaps = 2,
          .dropped_poses = 5, .rejected_messages = 1, .knot = "trefoil",
          .knot_determinant = 3, .contacts = 2, .max_update_hz = 100.0, .refusals = "device/bad-mac=1",
          .epoch = 0, .auth_seq = 0, .sender_role = 0, .sender_name = "", .key_expires = 0,
          .key_id = 0, .signature = {}, .signature2 = {}, .mac = {}};
}

inline device_status_t Sample(const device_status_t*) {
  return {.utime = 11, .seq = 12, .device_id = "sim-path", .tick_rate_hz = 1000.0,
          .lateness_us_p50 = 50, .lateness_us_p99 = 120, .lateness_us_max = 900,
          .model_age_ms = 1.5, .round_trip_us_p50 = 400, .round_trip_us_p99 = 1200,
          .force_norm_n = 0.7, .ticks = 10000, .models_received = 9000, .models_rejected = 1,
          .force_clamps = 2, .stiffness_clamps = 3, .slew_limits = 4, .fades = 5,
          .snaps_felt = 6, .grasp = "",
          .snap_ahead_switches = 1, .device_public_key = {}, .device_certificate = {},
          .epoch = 0, .auth_seq = 0, .sender_role = 0, .sender_name = "", .key_expires = 0,
          .key_id = 0, .signature = {}, .signature2 = {}, .mac = {}};
}

inline command_t Sample(const command_t*) {
  return {.utime = 13, .command = command_t::LOAD_SCENE, .argument = "scenes/zeeman.yaml",
          .epoch = 0, .auth_seq = 0, .sender_role = 0, .sender_name = "", .key_expires = 0,
          .key_id = 0, .signature = {}, .signature2 = {}, .mac = {}};
}

inline command_reply_t Sample(const command_reply_t*) {
  return {.utime = 14, .seq = 3, .command_auth_seq = 1700000000000000001, .command = command_t::LOAD_SCENE,
          .ok = 1, .message = "LOAD_SCENE: now scene 'zeeman' (zeeman)", .epoch = 0, .auth_seq = 0, .sender_role = 0, .sender_name = "", .key_expires = 0,
          .key_id = 0, .signature = {}, .signature2 = {}, .mac = {}};
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

}  // namespace snapthread::test_support
