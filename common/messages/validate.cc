#include "messages/validate.h"

#include <cmath>
#include <cstdint>
#include <limits>
#include <span>

namespace snapthread::messages {
namespace {

constexpr int64_t kInt32Max = std::numeric_limits<int32_t>::max();

bool Fail(std::string* why, const std::string& text) {
  if (why) *why = text;
  return false;
}

// ---- rules of their own --------------------------------------------------------------------

bool UnitQuaternion(const double (&q)[4], const char* name, std::string* why) {
  double n2 = 0.0;
  for (double v : q) n2 += v * v;
  const double n = std::sqrt(n2);
  if (n < kMinQuaternionNorm || n > kMaxQuaternionNorm) {
    return Fail(why, std::string(name) + " quaternion norm " + std::to_string(n) +
                         " outside [" + std::to_string(kMinQuaternionNorm) + ", " +
                         std::to_string(kMaxQuaternionNorm) + "]");
  }
  return true;
}

bool QuaternionNorm(const device_state_t& msg, std::string* why) {
  return UnitQuaternion(msg.orientation, "orientation", why);
}

// A force model's expansion orientation must be a quaternion when the wrench is used.
bool WrenchOrientation(const force_model_t& msg, std::string* why) {
  return msg.has_wrench == 0 || UnitQuaternion(msg.q0, "q0", why);
}

// A fold boundary's normal (fold_normal, fold_normal_r: position and rotation parts) must
// be a unit vector, and its orientation a quaternion, when the fold is used.
bool FoldNormal(const force_model_t& msg, std::string* why) {
  if (msg.has_fold == 0) return true;
  double n2 = 0.0;
  for (double v : msg.fold_normal) n2 += v * v;
  for (double v : msg.fold_normal_r) n2 += v * v;
  if (std::abs(std::sqrt(n2) - 1.0) > 1e-3) {
    return Fail(why, "(fold_normal, fold_normal_r) is not a unit vector (norm " + std::to_string(std::sqrt(n2)) + ")");
  }
  return true;
}

bool FoldOrientation(const force_model_t& msg, std::string* why) {
  return msg.has_fold == 0 || UnitQuaternion(msg.fold_q, "fold_q", why);
}

// Rows of a variable array: as many as its count says, `per_row` finite values each.
template <auto Rows, auto Count, int PerRow>
bool CountedRowsAgree(const thread_shape_t& msg, std::string* why) {
  const auto& rows = msg.*Rows;
  const std::string name = Rows == &thread_shape_t::positions ? "positions"
                           : Rows == &thread_shape_t::frames  ? "frames"
                           : Rows == &thread_shape_t::grasps  ? "grasps"
                                                              : "contacts";
  const std::string count = Count == &thread_shape_t::num_nodes    ? "num_nodes"
                            : Count == &thread_shape_t::num_frames ? "num_frames"
                            : Count == &thread_shape_t::num_grasps ? "num_grasps"
                                                                   : "num_contacts";
  if (rows.size() != static_cast<size_t>(msg.*Count)) {
    return Fail(why, name + " has " + std::to_string(rows.size()) + " rows, " + count + " says " +
                         std::to_string(msg.*Count));
  }
  for (size_t i = 0; i < rows.size(); ++i) {
    const auto& row = rows[i];
    if (row.size() != static_cast<size_t>(PerRow)) {
      return Fail(why, name + " row " + std::to_string(i) + " has " + std::to_string(row.size()) +
                           " entries, expected " + std::to_string(PerRow));
    }
    for (double v : row) {
      if (!std::isfinite(v)) return Fail(why, name + " row " + std::to_string(i) + " is not finite");
    }
  }
  return true;
}

// ---- one table per message type: its fields in .lcm order (lcmtypes/*.lcm) -----------------
// Every double must be finite and every string at most kMaxStringBytes (Member's default);
// the ranges below are the rest. The authentication trailer (epoch ... mac) is
// checked by the receiver's auth layer (common/auth), not here.

using D = device_state_t;
const Field<D> kDeviceState[] = {
    Member<&D::utime>("utime"),
    Member<&D::seq>("seq"),
    Member<&D::device_id>("device_id"),
    Member<&D::position>("position"),
    With(Member<&D::orientation>("orientation"), &QuaternionNorm),
    Member<&D::buttons>("buttons"),
    Member<&D::grasp>("grasp"),
    Member<&D::snap_fold_id>("snap_fold_id"),
    Member<&D::epoch>("epoch"),  // authentication (docs/security.md)
    Member<&D::auth_seq>("auth_seq"),
    Member<&D::sender_role>("sender_role", 0, 3),
    Member<&D::sender_name>("sender_name"),
    Member<&D::key_expires>("key_expires"),
    Member<&D::key_id>("key_id"),
    Member<&D::signature>("signature"),
    Member<&D::signature2>("signature2"),
    Member<&D::mac>("mac"),
};

using F = force_model_t;
const Field<F> kForceModel[] = {
    Member<&F::utime>("utime"),
    Member<&F::seq>("seq"),
    Member<&F::device_seq>("device_seq"),
    Member<&F::device_utime>("device_utime"),
    Member<&F::server_receive_utime>("server_receive_utime"),
    Member<&F::solve_us>("solve_us", 0, kInt32Max),
    Member<&F::status>("status", F::STATUS_REGULAR, F::STATUS_SNAPPING),
    Member<&F::u0>("u0"),
    Member<&F::f0>("f0"),
    Member<&F::K>("K"),
    Member<&F::has_torque>("has_torque", 0, 1),
    Member<&F::torque0>("torque0"),
    Member<&F::iterations>("iterations", 0, kInt32Max),
    Member<&F::residual>("residual"),
    Member<&F::has_wrench>("has_wrench", 0, 1),
    With(Member<&F::q0>("q0"), &WrenchOrientation),
    Member<&F::K6>("K6"),
    Member<&F::grasp>("grasp"),
    Member<&F::has_fold>("has_fold", 0, 1),
    Member<&F::fold_id>("fold_id"),
    Member<&F::fold_point>("fold_point"),
    Member<&F::fold_normal>("fold_normal"),
    Member<&F::fold_curvature>("fold_curvature"),
    Member<&F::post_u0>("post_u0"),
    Member<&F::post_f0>("post_f0"),
    Member<&F::post_K>("post_K"),
    With(Member<&F::fold_q>("fold_q"), &FoldOrientation),
    With(Member<&F::fold_normal_r>("fold_normal_r"), &FoldNormal),
    Member<&F::post_torque0>("post_torque0"),
    Member<&F::force_error_n>("force_error_n"),
    Member<&F::epoch>("epoch"),  // authentication (docs/security.md)
    Member<&F::auth_seq>("auth_seq"),
    Member<&F::sender_role>("sender_role", 0, 3),
    Member<&F::sender_name>("sender_name"),
    Member<&F::key_expires>("key_expires"),
    Member<&F::key_id>("key_id"),
    Member<&F::signature>("signature"),
    Member<&F::signature2>("signature2"),
    Member<&F::mac>("mac"),
};

using S = thread_shape_t;
const Field<S> kThreadShape[] = {
    Member<&S::utime>("utime"),
    Member<&S::seq>("seq"),
    Member<&S::scene>("scene"),
    Member<&S::model>("model"),
    Count<&S::num_nodes>("num_nodes", 0, kMaxShapeNodes),
    CountedRows<S>("positions", 3, &CountedRowsAgree<&S::positions, &S::num_nodes, 3>),
    Member<&S::grasp>("grasp"),
    Member<&S::grip_direction>("grip_direction"),
    Member<&S::force>("force"),
    Member<&S::force_newtons>("force_newtons"),
    Member<&S::status>("status", F::STATUS_REGULAR, F::STATUS_SNAPPING),
    Member<&S::snaps>("snaps"),
    Count<&S::num_frames>("num_frames", 0, kMaxShapeNodes),
    CountedRows<S>("frames", 4, &CountedRowsAgree<&S::frames, &S::num_frames, 4>),
    Member<&S::grasp_names>("grasp_names"),
    Count<&S::num_grasps>("num_grasps", 0, kMaxGrasps),
    CountedRows<S>("grasps", 6, &CountedRowsAgree<&S::grasps, &S::num_grasps, 6>),
    Count<&S::num_contacts>("num_contacts", 0, kMaxShapeNodes),
    CountedRows<S>("contacts", 6, &CountedRowsAgree<&S::contacts, &S::num_contacts, 6>),
    Member<&S::knot>("knot"),
    Member<&S::epoch>("epoch"),  // authentication (docs/security.md)
    Member<&S::auth_seq>("auth_seq"),
    Member<&S::sender_role>("sender_role", 0, 3),
    Member<&S::sender_name>("sender_name"),
    Member<&S::key_expires>("key_expires"),
    Member<&S::key_id>("key_id"),
    Member<&S::signature>("signature"),
    Member<&S::signature2>("signature2"),
    Member<&S::mac>("mac"),
};

using V = solver_status_t;
const Field<V> kSolverStatus[] = {
    Member<&V::utime>("utime"),
    Member<&V::seq>("seq"),
    Member<&V::scene>("scene"),
    Member<&V::method>("method"),
    Member<&V::iterations>("iterations"),
    Member<&V::residual>("residual"),
    Member<&V::lambda_min>("lambda_min"),
    Member<&V::negative_pivots>("negative_pivots"),
    Member<&V::status>("status", F::STATUS_REGULAR, F::STATUS_SNAPPING),
    Member<&V::update_rate_hz>("update_rate_hz"),
    Member<&V::solve_us_p50>("solve_us_p50"),
    Member<&V::solve_us_p99>("solve_us_p99"),
    Member<&V::updates>("updates"),
    Member<&V::snaps>("snaps"),
    Member<&V::dropped_poses>("dropped_poses"),
    Member<&V::rejected_messages>("rejected_messages"),
    Member<&V::knot>("knot"),
    Member<&V::knot_determinant>("knot_determinant", 0, kInt32Max),
    Member<&V::contacts>("contacts", 0, kInt32Max),
    Member<&V::max_update_hz>("max_update_hz"),
    Member<&V::refusals>("refusals"),
    Member<&V::epoch>("epoch"),  // authentication (docs/security.md)
    Member<&V::auth_seq>("auth_seq"),
    Member<&V::sender_role>("sender_role", 0, 3),
    Member<&V::sender_name>("sender_name"),
    Member<&V::key_expires>("key_expires"),
    Member<&V::key_id>("key_id"),
    Member<&V::signature>("signature"),
    Member<&V::signature2>("signature2"),
    Member<&V::mac>("mac"),
};

using T = device_status_t;
const Field<T> kDeviceStatus[] = {
    Member<&T::utime>("utime"),
    Member<&T::seq>("seq"),
    Member<&T::device_id>("device_id"),
    Member<&T::tick_rate_hz>("tick_rate_hz"),
    Member<&T::lateness_us_p50>("lateness_us_p50"),
    Member<&T::lateness_us_p99>("lateness_us_p99"),
    Member<&T::lateness_us_max>("lateness_us_max"),
    Member<&T::model_age_ms>("model_age_ms"),
    Member<&T::round_trip_us_p50>("round_trip_us_p50"),
    Member<&T::round_trip_us_p99>("round_trip_us_p99"),
    Member<&T::force_norm_n>("force_norm_n"),
    Member<&T::ticks>("ticks"),
    Member<&T::models_received>("models_received"),
    Member<&T::models_rejected>("models_rejected"),
    Member<&T::force_clamps>("force_clamps"),
    Member<&T::stiffness_clamps>("stiffness_clamps"),
    Member<&T::slew_limits>("slew_limits"),
    Member<&T::fades>("fades"),
    Member<&T::snaps_felt>("snaps_felt"),
    Member<&T::grasp>("grasp"),
    Member<&T::snap_ahead_switches>("snap_ahead_switches"),
    Member<&T::device_public_key>("device_public_key"),
    Member<&T::device_certificate>("device_certificate"),
    Member<&T::epoch>("epoch"),  // authentication (docs/security.md)
    Member<&T::auth_seq>("auth_seq"),
    Member<&T::sender_role>("sender_role", 0, 3),
    Member<&T::sender_name>("sender_name"),
    Member<&T::key_expires>("key_expires"),
    Member<&T::key_id>("key_id"),
    Member<&T::signature>("signature"),
    Member<&T::signature2>("signature2"),
    Member<&T::mac>("mac"),
};

using C = command_t;
const Field<C> kCommand[] = {
    Member<&C::utime>("utime"),
    Member<&C::command>("command", C::RESET, C::SET_METHOD),
    Member<&C::argument>("argument"),
    Member<&C::epoch>("epoch"),  // authentication (docs/security.md)
    Member<&C::auth_seq>("auth_seq"),
    Member<&C::sender_role>("sender_role", 0, 3),
    Member<&C::sender_name>("sender_name"),
    Member<&C::key_expires>("key_expires"),
    Member<&C::key_id>("key_id"),
    Member<&C::signature>("signature"),
    Member<&C::signature2>("signature2"),
    Member<&C::mac>("mac"),
};

// A reply's message is short text for a terminal (the operator's console prints it).
bool ReplyMessageLength(const command_reply_t& msg, std::string* why) {
  if (msg.message.size() <= static_cast<size_t>(kMaxCommandReplyBytes)) return true;
  return Fail(why, "message longer than " + std::to_string(kMaxCommandReplyBytes) + " bytes");
}

using R = command_reply_t;
const Field<R> kCommandReply[] = {
    Member<&R::utime>("utime"),
    Member<&R::seq>("seq"),
    Member<&R::command_auth_seq>("command_auth_seq"),
    Member<&R::command>("command", C::RESET, C::SET_METHOD),
    Member<&R::ok>("ok", 0, 1),
    With(Member<&R::message>("message"), &ReplyMessageLength),
    Member<&R::epoch>("epoch"),  // authentication (docs/security.md)
    Member<&R::auth_seq>("auth_seq"),
    Member<&R::sender_role>("sender_role", 0, 3),
    Member<&R::sender_name>("sender_name"),
    Member<&R::key_expires>("key_expires"),
    Member<&R::key_id>("key_id"),
    Member<&R::signature>("signature"),
    Member<&R::signature2>("signature2"),
    Member<&R::mac>("mac"),
};

std::span<const Field<D>> TableOf(const D*) { return kDeviceState; }
std::span<const Field<F>> TableOf(const F*) { return kForceModel; }
std::span<const Field<S>> TableOf(const S*) { return kThreadShape; }
std::span<const Field<V>> TableOf(const V*) { return kSolverStatus; }
std::span<const Field<T>> TableOf(const T*) { return kDeviceStatus; }
std::span<const Field<C>> TableOf(const C*) { return kCommand; }
std::span<const Field<R>> TableOf(const R*) { return kCommandReply; }

template <class M>
bool ValidateByTable(const M& msg, std::string* why) {
  return CheckFields(TableOf(static_cast<const M*>(nullptr)), msg, why);
}

}  // namespace

template <class M>
bool PreDecodeCheck(const void* data, int size, std::string* why) {
  return CheckWire(TableOf(static_cast<const M*>(nullptr)), data, size, why);
}
template bool PreDecodeCheck<device_state_t>(const void*, int, std::string*);
template bool PreDecodeCheck<force_model_t>(const void*, int, std::string*);
template bool PreDecodeCheck<thread_shape_t>(const void*, int, std::string*);
template bool PreDecodeCheck<solver_status_t>(const void*, int, std::string*);
template bool PreDecodeCheck<device_status_t>(const void*, int, std::string*);
template bool PreDecodeCheck<command_t>(const void*, int, std::string*);
template bool PreDecodeCheck<command_reply_t>(const void*, int, std::string*);

bool Validate(const device_state_t& msg, std::string* why) { return ValidateByTable(msg, why); }
bool Validate(const force_model_t& msg, std::string* why) { return ValidateByTable(msg, why); }
bool Validate(const thread_shape_t& msg, std::string* why) { return ValidateByTable(msg, why); }
bool Validate(const solver_status_t& msg, std::string* why) { return ValidateByTable(msg, why); }
bool Validate(const device_status_t& msg, std::string* why) { return ValidateByTable(msg, why); }
bool Validate(const command_t& msg, std::string* why) { return ValidateByTable(msg, why); }
bool Validate(const command_reply_t& msg, std::string* why) { return ValidateByTable(msg, why); }

}  // namespace snapthread::messages
