#include "server_messages.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

#include "messages/pose_mapping.h"
#include "messages/validate.h"
#include "models/contact_capability.h"
#include "shape_frames.h"
#include "server_wrench.h"

namespace snapthread::server {
namespace {

bool Finite(double v) { return std::isfinite(v); }

bool ResultIsUsable(const TrackResult& r, int num_controls) {
  if (!r.summary.IsSolutionUsable()) return false;
  if (r.force.size() != num_controls || r.stiffness.rows() != num_controls ||
      r.stiffness.cols() != num_controls) {
    return false;
  }
  return r.force.allFinite() && r.stiffness.allFinite();
}

void ZeroForceModel(force_model_t* m) {
  for (int i = 0; i < 3; ++i) {
    m->f0[i] = 0.0;
    m->torque0[i] = 0.0;
    for (int j = 0; j < 3; ++j) m->K[i][j] = 0.0;
  }
  m->has_torque = 0;
  m->has_wrench = 0;
  m->q0[0] = 1.0;
  m->q0[1] = m->q0[2] = m->q0[3] = 0.0;
  for (auto& row : m->K6) {
    for (double& k : row) k = 0.0;
  }
}

}  // namespace

int8_t ClassifyStatus(const TrackResult* result) {
  if (result == nullptr || !result->summary.IsSolutionUsable() || !result->force.allFinite() ||
      !result->stiffness.allFinite()) {
    return force_model_t::STATUS_INVALID;
  }
  // The equilibrium status was decided once (DecideStatus: the tracker knows whether the
  // state changed branch; the solver's own snap flag only says its minimiser ran). The
  // message adds only what it knows itself: K was floored although the state is regular.
  switch (result->summary.status) {
    case EquilibriumStatus::kSnapped: return force_model_t::STATUS_SNAPPED;
    case EquilibriumStatus::kNearFold: return force_model_t::STATUS_NEAR_FOLD;
    case EquilibriumStatus::kSnapping: return force_model_t::STATUS_SNAPPING;
    case EquilibriumStatus::kFailed: return force_model_t::STATUS_INVALID;
    case EquilibriumStatus::kRegular: break;
  }
  return result->stiffness_regularized ? force_model_t::STATUS_NEAR_FOLD : force_model_t::STATUS_REGULAR;
}

double PlanarStiffness(const DeviceMapping& mapping) {
  return 0.5 * mapping.max_stiffness_n_per_m;
}

namespace {

// The rod's grasp u = (p, φ): the wrench in the pose chart (server_wrench.h). Device
// units: forces x N (n_per_f), torques x N/s (energy -> N m), position columns x s (per
// model length -> per metre), rotation columns in radians as they are. Nothing when the
// chart is singular there.
void FillWrench(const Eigen::Matrix<double, 6, 1>& u, const Eigen::Matrix<double, 6, 1>& force,
                const Mat6& stiffness, double n_per_f, double s, force_model_t* m) {
  GraspWrench w;
  if (!GraspWrenchFromControls(u, force, stiffness, &w)) return;
  const double row_scale[6] = {n_per_f, n_per_f, n_per_f, n_per_f / s, n_per_f / s, n_per_f / s};
  const double col_scale[6] = {s, s, s, 1.0, 1.0, 1.0};
  for (int i = 0; i < 6; ++i) {
    for (int j = 0; j < 6; ++j) m->K6[i][j] = row_scale[i] * col_scale[j] * w.k6(i, j);
  }
  for (int i = 0; i < 3; ++i) m->torque0[i] = (n_per_f / s) * w.torque[i];
  for (int i = 0; i < 4; ++i) m->q0[i] = w.q0[i];
  m->has_torque = 1;
  m->has_wrench = 1;
}

}  // namespace

force_model_t BuildForceModel(const ForceModelInputs& in) {
  force_model_t m{};
  m.utime = in.utime;
  m.seq = in.seq;
  m.device_seq = in.device_seq;
  m.device_utime = in.device_utime;
  m.server_receive_utime = in.server_receive_utime;
  const double solve_us = Finite(in.solve_us) ? std::clamp(in.solve_us, 0.0, 2.0e9) : 0.0;
  m.solve_us = static_cast<int32_t>(std::lround(solve_us));
  for (int i = 0; i < 3; ++i) m.u0[i] = Finite(in.position_m[i]) ? in.position_m[i] : 0.0;
  ZeroForceModel(&m);
  m.iterations = 0;
  m.residual = 0.0;
  m.force_error_n = -1.0;
  m.status = force_model_t::STATUS_INVALID;
  if (in.mapping == nullptr || in.model == nullptr || in.result == nullptr) return m;

  const DeviceMapping& map = *in.mapping;
  const Model& model = *in.model;
  const TrackResult& r = *in.result;
  const int nu = model.NumControls();
  const int dim = std::min(model.SpatialDimension(), 3);
  m.iterations = r.summary.iterations;
  m.residual = Finite(r.summary.residual) ? r.summary.residual : 0.0;
  const int off = in.grasp_offset;
  const int gnu = in.grasp_controls > 0 ? in.grasp_controls : nu;
  if (!ResultIsUsable(r, nu) || in.u.size() != nu || dim > gnu || off < 0 || off + gnu > nu) return m;

  // Device force F_dev = N F_model; u_model = origin + s p  =>  dF_dev/dp = N s K_model.
  const double n_per_f = map.newtons_per_model_force;
  const double s = map.model_units_per_metre;
  // The solve's certified force error (docs/accuracy.md), in newtons; -1: none.
  const double force_error = r.summary.force_error;
  m.force_error_n = Finite(force_error) && force_error >= 0.0 ? n_per_f * force_error : -1.0;
  for (int i = 0; i < dim; ++i) {
    m.f0[i] = n_per_f * r.force[off + i];
    for (int j = 0; j < dim; ++j) m.K[i][j] = n_per_f * s * r.stiffness(off + i, off + j);
  }
  if (dim == 2) {
    // Planar models have no z: without a constraint the hand would drift freely out of
    // the plane the thread lives in and the force would act on a point the user cannot
    // locate. A stiff virtual plane f_z = -k (z - z0) holds the grasp on the model plane.
    // k is half the scene's max stable stiffness: stiff enough to feel like a wall, with
    // headroom for the device client's stiffness clamp, latency and the 1 kHz sample
    // rate (a spring at the stability limit would buzz).
    const double k_plane = PlanarStiffness(map);
    m.f0[2] = -k_plane * (m.u0[2] - messages::PlanarZ0(map));
    m.K[2][2] = -k_plane;
  }
  const bool rotation = in.layout != nullptr && in.layout->grip_rotation;
  const bool grip = in.layout != nullptr ? in.layout->grip_direction : gnu >= dim + 3;
  if (rotation && dim == 3 && gnu >= 6) {
    FillWrench(in.u.segment<6>(off), r.force.segment<6>(off), r.stiffness.block<6, 6>(off, off),
               n_per_f, s, &m);
  } else if (grip && gnu >= dim + 3 && dim == 3) {
    // Grip direction d = u[3:6] (unit): the generalised force F_d = -E_d gives the torque
    // on the grip tau = d x F_d (a rotation w moves d by w x d, dE = w . (d x E_d)).
    // F_d is in model energy units = model force x model length: N / (units per metre).
    const Eigen::Vector3d d = in.u.segment<3>(off + 3).normalized();
    const Eigen::Vector3d fd = r.force.segment<3>(off + 3);
    const Eigen::Vector3d tau = d.cross(fd) * (n_per_f / s);
    for (int i = 0; i < 3; ++i) m.torque0[i] = tau[i];
    m.has_torque = 1;
  }
  m.status = ClassifyStatus(&r);
  // The one force-model check (messages/validate.cc); on failure the device renders zero.
  if (!messages::Validate(m, nullptr)) {
    ZeroForceModel(&m);
    m.status = force_model_t::STATUS_INVALID;
  }
  return m;
}

thread_shape_t BuildShape(const ShapeInputs& in) {
  thread_shape_t msg{};
  msg.utime = in.utime;
  msg.seq = in.seq;
  msg.scene = in.scene;
  msg.status = in.status;
  msg.snaps = in.snaps;
  msg.knot = in.knot;
  for (int i = 0; i < 3; ++i) {
    msg.grasp[i] = 0.0;
    msg.grip_direction[i] = 0.0;
    msg.force[i] = 0.0;
    msg.force_newtons[i] = Finite(in.force_newtons[i]) ? in.force_newtons[i] : 0.0;
  }
  msg.num_nodes = 0;
  if (in.model == nullptr) return msg;
  const Model& model = *in.model;
  msg.model = std::string(model.Name());
  const int dim = std::min(model.SpatialDimension(), 3);
  Eigen::Matrix3Xd nodes;
  if (in.x.size() == model.NumStates() && in.u.size() == model.NumControls()) {
    model.NodePositions(in.x, in.u, &nodes);
  }
  // Counts are validated by the receiver, but the encoder trusts num_nodes: keep them equal.
  msg.num_nodes = static_cast<int32_t>(nodes.cols());
  msg.positions.assign(nodes.cols(), std::vector<double>(3, 0.0));
  for (Eigen::Index k = 0; k < nodes.cols(); ++k) {
    for (int i = 0; i < 3; ++i) msg.positions[k][i] = Finite(nodes(i, k)) ? nodes(i, k) : 0.0;
  }
  // The rod's material frames and twist (shape_frames.h); none for other models.
  if (nodes.cols() > 0) FillShapeFrames(model, in.x, in.u, &msg);
  for (int i = 0; i < dim && i < in.u.size(); ++i) msg.grasp[i] = in.u[i];
  if (msg.num_frames > 0 && nodes.cols() >= 2) {
    // The rod: u[3:6] is a rotation vector φ, not a direction. The grip direction is
    // R(u) e_x, the held edge's tangent: x_n - x_{n-1} for the grasp of edge n-1, or,
    // when the first grasp holds edge 0 (12 controls; msg.grasp is that one), x_1 - x_0.
    const Eigen::Index last = nodes.cols() - 1;
    const Eigen::Vector3d d = (in.u.size() >= 12 ? Eigen::Vector3d(nodes.col(1) - nodes.col(0))
                                                 : Eigen::Vector3d(nodes.col(last) - nodes.col(last - 1)))
                                  .normalized();
    for (int i = 0; i < 3; ++i) msg.grip_direction[i] = Finite(d[i]) ? d[i] : 0.0;
  } else if (dim == 3 && in.u.size() >= 6) {
    const Eigen::Vector3d d = in.u.segment<3>(3).normalized();
    for (int i = 0; i < 3; ++i) msg.grip_direction[i] = Finite(d[i]) ? d[i] : 0.0;
  }
  for (int i = 0; i < dim && i < in.force_model_units.size(); ++i) {
    msg.force[i] = Finite(in.force_model_units[i]) ? in.force_model_units[i] : 0.0;
  }
  // Self-contact: the closest points of each active pair (none without contact).
  const ContactCapability* const self_contact = model.contact();
  if (nodes.cols() > 0 && self_contact != nullptr) {
    for (const contact::ContactPoint& c : self_contact->ActiveContacts(in.x, in.u)) {
      std::vector<double> row(6, 0.0);
      for (int i = 0; i < 3; ++i) {
        row[i] = Finite(c.point_a[i]) ? c.point_a[i] : 0.0;
        row[3 + i] = Finite(c.point_b[i]) ? c.point_b[i] : 0.0;
      }
      msg.contacts.push_back(row);
    }
    msg.num_contacts = static_cast<int32_t>(msg.contacts.size());
  }
  return msg;
}

solver_status_t BuildSolverStatus(const StatusInputs& in) {
  solver_status_t msg{};
  msg.utime = in.utime;
  msg.seq = in.seq;
  msg.scene = in.scene;
  msg.method = in.method;
  msg.iterations = 0;
  msg.residual = 0.0;
  msg.lambda_min = 0.0;
  msg.negative_pivots = 0;
  if (in.summary != nullptr) {
    msg.iterations = in.summary->iterations;
    msg.residual = Finite(in.summary->residual) ? in.summary->residual : 0.0;
    msg.lambda_min = Finite(in.summary->lambda_min) ? in.summary->lambda_min : 0.0;
    msg.negative_pivots = in.summary->negative_pivots;
  }
  msg.status = in.status;
  msg.update_rate_hz = Finite(in.update_rate_hz) ? in.update_rate_hz : 0.0;
  msg.solve_us_p50 = Finite(in.solve_us_p50) ? in.solve_us_p50 : 0.0;
  msg.solve_us_p99 = Finite(in.solve_us_p99) ? in.solve_us_p99 : 0.0;
  msg.updates = in.updates;
  msg.snaps = in.snaps;
  msg.dropped_poses = in.dropped_poses;
  msg.rejected_messages = in.rejected_messages;
  msg.refusals = in.refusals;
  msg.contacts = in.contacts;
  msg.knot = in.knot;
  msg.knot_determinant = in.knot_determinant;
  msg.max_update_hz = Finite(in.max_update_hz) ? in.max_update_hz : 0.0;
  return msg;
}

}  // namespace snapthread::server
