// Building the server's outgoing messages, separate from sending them (cf. Drake's
// manipulation/kuka_iiwa/iiwa_command_sender.h): pure functions of the solve result, so
// tests check units and flags without any transport.
#pragma once

#include <cstdint>
#include <string>

#include <Eigen/Core>

#include "snapthread/force_model_t.hpp"
#include "models/model.h"
#include "scene/scene.h"
#include "snapthread/solver_status_t.hpp"
#include "snapthread/thread_shape_t.hpp"
#include "tracking/tracker.h"
#include "numeric/types.h"

namespace snapthread::server {

// force_model_t.STATUS_* for one update: the decided summary.status (DecideStatus,
// solvers/summary.h) as a message status. result == nullptr means the update failed
// (threw): INVALID. A result that is not usable (!summary.IsSolutionUsable(): linear
// solver failed, non-finite, invalid input) or not finite is INVALID too; a spent budget
// is not (the state is the last accepted one and the force is usable). A regular state
// whose stiffness was regularised is NEAR_FOLD (the device gets a floored K).
int8_t ClassifyStatus(const TrackResult* result);

// The planar constraint's stiffness for planar models, N/m (see BuildForceModel).
double PlanarStiffness(const DeviceMapping& mapping);

// The local force model F(p) = f0 + K (p - u0) in device units around the pose p = u0
// (metres), for the controls u the pose mapped to. `result` is the tracker's result for
// u (nullptr if the update failed). Never contains NaN/Inf: anything non-finite turns the
// message into STATUS_INVALID with zero force and stiffness.
struct ForceModelInputs {
  const DeviceMapping* mapping = nullptr;
  const Model* model = nullptr;
  Vec u;                              // controls the pose mapped to, model units
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();  // the pose, device metres
  const TrackResult* result = nullptr;
  int64_t device_seq = 0;
  int64_t device_utime = 0;           // echoed: the device's CLOCK_MONOTONIC
  int64_t server_receive_utime = 0;   // CLOCK_REALTIME when the pose arrived
  double solve_us = 0.0;
  int64_t seq = 0;
  int64_t utime = 0;                  // CLOCK_REALTIME now
  // The grasp the model is for: its controls u[offset, offset + count) and its
  // block of F and K (count 0: all the model's controls, the single grasp). The server's
  // predictor keeps the cross terms; the device gets its own block.
  int grasp_offset = 0;
  int grasp_controls = 0;
  // The controls of one grasp (Scene::grasp_layout). A grip direction adds the torque on
  // the grip; a full orientation (the rod) adds the wrench: torque0, q0 and K6 in the
  // pose chart (server_wrench.h). nullptr: a grip direction when the grasp has 3
  // controls more than its position (the layouts before the rod).
  const GraspLayout* layout = nullptr;
};
force_model_t BuildForceModel(const ForceModelInputs& in);

struct ShapeInputs {
  std::string scene;
  const DeviceMapping* mapping = nullptr;
  const Model* model = nullptr;
  Vec x;                 // state, model units
  Vec u;                 // controls, model units
  Vec force_model_units; // F = -E_u (size NumControls; may be empty before the first update)
  Eigen::Vector3d force_newtons = Eigen::Vector3d::Zero();
  int8_t status = force_model_t::STATUS_REGULAR;
  int64_t snaps = 0;
  std::string knot;      // the shape's knot type (KnotWatch), "" = not computed
  int64_t seq = 0;
  int64_t utime = 0;
};
thread_shape_t BuildShape(const ShapeInputs& in);

struct StatusInputs {
  std::string scene;
  std::string method;
  const SolverSummary* summary = nullptr;  // of the last update (nullptr: none yet)
  int8_t status = force_model_t::STATUS_REGULAR;
  double update_rate_hz = 0.0;
  double solve_us_p50 = 0.0;
  double solve_us_p99 = 0.0;
  int64_t updates = 0;
  int64_t snaps = 0;
  int64_t dropped_poses = 0;
  int64_t rejected_messages = 0;
  std::string refusals;  // "role/reason=count ..." (refusal_counts.h)
  int32_t contacts = 0;  // active self-contact pairs at the last update
  std::string knot;              // KnotWatch: "" = not computed
  int32_t knot_determinant = 0;  // 0 = not computed
  double max_update_hz = 0.0;  // the update cap in force (0 = none)
  int64_t seq = 0;
  int64_t utime = 0;
};
solver_status_t BuildSolverStatus(const StatusInputs& in);

}  // namespace snapthread::server
