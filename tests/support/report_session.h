// A session as snapthread-report reads it back from a log, for the report's tests
// (tests/viewer/report_test.cc) and the hostile log's (tests/attack/report_injection_test.cc):
// at step k (k = 1, 2, ... one a millisecond) a pose and its force model, at every 10th step
// a shape and a solver status, at every 40th a device status. The model of step 100
// snapped; contacts from step 100, the knot tied at 150. And what a plot of the report
// must look like. Header-only: for the test binaries that link the LCM types and
// png_image (tests/viewer).
#pragma once

#include <cstddef>
#include <cstdint>
#include <set>
#include <string>

#include <gtest/gtest.h>

#include "png_image.h"

#include "snapthread/device_state_t.hpp"
#include "snapthread/device_status_t.hpp"
#include "snapthread/force_model_t.hpp"
#include "snapthread/solver_status_t.hpp"
#include "snapthread/thread_shape_t.hpp"

namespace snapthread::test_support {

// Designated initializers name every field (as sample_messages.h): with -Wextra
// (missing-field-initializers) a field added to a type fails the build here until the
// session sets it. Unsigned: epoch, auth_seq and mac zero.

inline device_state_t ReportPose(int k, const std::string& device_id) {
  return {.utime = k * 1000, .seq = k, .device_id = device_id, .position = {},
          .orientation = {1.0, 0.0, 0.0, 0.0}, .buttons = 1, .grasp = "", .snap_fold_id = 0,
          .epoch = 0, .auth_seq = 0, .sender_role = 0, .sender_name = "", .key_expires = 0,
          .key_id = 0, .signature = {}, .signature2 = {}, .mac = {}};
}

// The answer to pose `seq`, its server times from t0_us: |F| grows to 2.0 N at seq 200.
inline force_model_t ReportModel(int seq, int64_t t0_us) {
  return {.utime = t0_us + seq * 1000 + 500, .seq = seq, .device_seq = seq, .device_utime = seq * 1000,
          .server_receive_utime = t0_us + seq * 1000 + 100, .solve_us = 200 + seq % 7,
          .status = seq == 100 ? force_model_t::STATUS_SNAPPED : force_model_t::STATUS_REGULAR,
          .u0 = {}, .f0 = {0.01 * seq, 0.0, 0.0},
          .K = {{-50.0, 0.0, 0.0}, {0.0, -50.0, 0.0}, {0.0, 0.0, -50.0}}, .has_torque = 0,
          .torque0 = {}, .iterations = 2 + (seq == 100 ? 17 : 0), .residual = 1e-11,
          .has_wrench = 0, .q0 = {}, .K6 = {}, .grasp = "", .has_fold = 0, .fold_id = 0,
          .fold_point = {}, .fold_normal = {}, .fold_curvature = 0.0, .post_u0 = {}, .post_f0 = {},
          .post_K = {}, .fold_q = {}, .fold_normal_r = {}, .post_torque0 = {},
          .force_error_n = 1e-6 * seq,
          .epoch = 0, .auth_seq = 0, .sender_role = 0, .sender_name = "", .key_expires = 0,
          .key_id = 0, .signature = {}, .signature2 = {}, .mac = {}};
}

// Steps k = 10, 20, ...: a two-node curve2d shape published at t_us.
inline thread_shape_t ReportShape(int k, int64_t t_us, const std::string& scene) {
  return {.utime = t_us, .seq = k / 10, .scene = scene, .model = "curve2d", .num_nodes = 2,
          .positions = {{0.0, 0.0, 0.0}, {1.0, 0.0, 0.0}}, .grasp = {}, .grip_direction = {},
          .force = {}, .force_newtons = {}, .status = force_model_t::STATUS_REGULAR,
          .snaps = k > 100 ? 1 : 0, .num_frames = 0, .frames = {}, .grasp_names = "",
          .num_grasps = 0, .grasps = {}, .num_contacts = 0, .contacts = {}, .knot = "",
          .epoch = 0, .auth_seq = 0, .sender_role = 0, .sender_name = "", .key_expires = 0,
          .key_id = 0, .signature = {}, .signature2 = {}, .mac = {}};
}

// Steps k = 10, 20, ...: Newton until step 100, the higher-order solver after it.
inline solver_status_t ReportSolverStatus(int k, int64_t t_us, const std::string& scene) {
  return {.utime = t_us, .seq = k / 10, .scene = scene,
          .method = k <= 100 ? "newton" : "higher-order", .iterations = 2, .residual = 1e-11,
          .lambda_min = 0.5, .negative_pivots = 0, .status = force_model_t::STATUS_REGULAR,
          .update_rate_hz = 1000.0, .solve_us_p50 = 200.0, .solve_us_p99 = 300.0, .updates = k,
          .snaps = 0, .dropped_poses = 0, .rejected_messages = 0,
          .knot = k < 150 ? "unknot" : "trefoil", .knot_determinant = k < 150 ? 1 : 3,
          .contacts = k < 100 ? 0 : k < 150 ? 2 : 4, .max_update_hz = 0.0, .refusals = "",
          .epoch = 0, .auth_seq = 0, .sender_role = 0, .sender_name = "", .key_expires = 0,
          .key_id = 0, .signature = {}, .signature2 = {}, .mac = {}};
}

// Steps k = 40, 80, ...: lateness growing, force clamps 0 .. 4 over the five statuses.
inline device_status_t ReportDeviceStatus(int k, const std::string& device_id) {
  return {.utime = k * 1000, .seq = k / 40, .device_id = device_id, .tick_rate_hz = 1000.0,
          .lateness_us_p50 = 5.0 + k / 40, .lateness_us_p99 = 40.0 + k / 10,
          .lateness_us_max = 90.0 + k / 10, .model_age_ms = 0.7, .round_trip_us_p50 = 700.0,
          .round_trip_us_p99 = 900.0, .force_norm_n = 0.01 * k, .ticks = k, .models_received = 0,
          .models_rejected = 0, .force_clamps = k / 40 - 1, .stiffness_clamps = 0,
          .slew_limits = 0, .fades = 0, .snaps_felt = 0, .grasp = "", .snap_ahead_switches = 0,
          .device_public_key = {}, .device_certificate = {},
          .epoch = 0, .auth_seq = 0, .sender_role = 0, .sender_name = "", .key_expires = 0,
          .key_id = 0, .signature = {}, .signature2 = {}, .mac = {}};
}

// A plot with real content: plot-sized, many colours and a good share of ink.
inline void ExpectRealPlot(const viewer_test::Image& img, const std::string& what) {
  EXPECT_GE(img.width, 400) << what;
  EXPECT_GE(img.height, 300) << what;
  std::set<uint32_t> colours;
  size_t ink = 0;
  for (int y = 0; y < img.height; ++y) {
    for (int x = 0; x < img.width; ++x) {
      const uint8_t* p = img.At(x, y);
      colours.insert(uint32_t(p[0]) << 16 | uint32_t(p[1]) << 8 | p[2]);
      ink += (p[0] < 200 || p[1] < 200 || p[2] < 200);
    }
  }
  EXPECT_GE(colours.size(), 8u) << what;
  EXPECT_GT(ink, size_t(img.width) * img.height / 100) << what << " is nearly blank";
}

}  // namespace snapthread::test_support
