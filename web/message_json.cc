#include "message_json.h"

#include <cmath>

#include "json_writer.h"
#include "models/registry.h"

namespace snapthread::web {
namespace {

void Vec3(JsonWriter* w, const char* key, const double (&v)[3]) { w->Numbers(key, v, 3); }

// Rows of a counted array of fixed-width rows, flattened.
template <class Rows>
void FlatRows(JsonWriter* w, const char* key, const Rows& rows) {
  w->BeginArray(key);
  for (const auto& row : rows) {
    for (const double v : row) w->Element(v);
  }
  w->EndArray();
}

// The fields this round adds to thread_shape_t (BRIEF4): written when the message type
// has them, so the bridge builds against either version of the lcmtypes.
template <class Shape>
void RoundFields(JsonWriter* w, const Shape& s) {
  if constexpr (requires { s.num_grasps; s.grasps; s.grasp_names; }) {
    w->String("grasp_names", s.grasp_names);
    FlatRows(w, "grasps", s.grasps);
  }
  if constexpr (requires { s.num_contacts; s.contacts; }) FlatRows(w, "contacts", s.contacts);
  if constexpr (requires { s.num_frames; s.frames; }) FlatRows(w, "frames", s.frames);
  if constexpr (requires { s.knot; }) w->String("knot", s.knot);
}

template <class Status>
void SolverRoundFields(JsonWriter* w, const Status& s) {
  if constexpr (requires { s.knot; s.contacts; }) {
    w->String("knot", s.knot).Int("contacts", s.contacts);
  }
  if constexpr (requires { s.max_update_hz; }) w->Number("max_update_hz", s.max_update_hz);
}

template <class Status>
void DeviceRoundFields(JsonWriter* w, const Status& s) {
  if constexpr (requires { s.grasp; s.snap_ahead_switches; }) {
    w->String("grasp", s.grasp).Int("snap_ahead_switches", s.snap_ahead_switches);
  }
}

}  // namespace

bool DrawsSmooth(const std::string& model) {
  const ModelRegistration* registration = FindModel(model);
  return registration != nullptr && registration->capabilities.chain.has_value();
}

std::string ShapeJson(const thread_shape_t& s, bool smooth) {
  JsonWriter w;
  w.BeginObject().String("type", "shape").Int("seq", s.seq).Int("utime", s.utime);
  w.String("scene", s.scene).String("model", s.model).Bool("smooth", smooth);
  w.Int("status", s.status).Int("snaps", s.snaps);
  FlatRows(&w, "positions", s.positions);
  Vec3(&w, "grasp", s.grasp);
  Vec3(&w, "grip", s.grip_direction);
  Vec3(&w, "force", s.force);
  Vec3(&w, "force_n", s.force_newtons);
  RoundFields(&w, s);
  return w.EndObject().Take();
}

std::string ForceModelJson(const force_model_t& m) {
  JsonWriter w;
  w.BeginObject().String("type", "force").Int("seq", m.seq).Int("utime", m.utime);
  w.Int("device_utime", m.device_utime).Int("server_receive_utime", m.server_receive_utime);
  w.Int("status", m.status).Int("solve_us", m.solve_us).Int("iterations", m.iterations);
  w.Number("residual", m.residual);
  // The certified force error of f0 in newtons; -1: none could be made (the page shows "none").
  w.Number("force_error_n", m.force_error_n);
  w.Number("f_n", std::sqrt(m.f0[0] * m.f0[0] + m.f0[1] * m.f0[1] + m.f0[2] * m.f0[2]));
  Vec3(&w, "f0", m.f0);
  Vec3(&w, "u0", m.u0);
  return w.EndObject().Take();
}

std::string SolverStatusJson(const solver_status_t& s) {
  JsonWriter w;
  w.BeginObject().String("type", "solver").Int("seq", s.seq).Int("utime", s.utime);
  w.String("scene", s.scene).String("method", s.method).Int("iterations", s.iterations);
  w.Number("residual", s.residual).Number("lambda_min", s.lambda_min);
  w.Int("negative_pivots", s.negative_pivots).Int("status", s.status);
  w.Number("update_rate_hz", s.update_rate_hz);
  w.Number("solve_us_p50", s.solve_us_p50).Number("solve_us_p99", s.solve_us_p99);
  w.Int("updates", s.updates).Int("snaps", s.snaps);
  w.Int("dropped_poses", s.dropped_poses).Int("rejected_messages", s.rejected_messages);
  SolverRoundFields(&w, s);
  return w.EndObject().Take();
}

std::string DeviceStatusJson(const device_status_t& s) {
  JsonWriter w;
  w.BeginObject().String("type", "device").Int("seq", s.seq).String("device_id", s.device_id);
  w.Number("tick_rate_hz", s.tick_rate_hz);
  w.Number("lateness_us_p50", s.lateness_us_p50).Number("lateness_us_p99", s.lateness_us_p99);
  w.Number("lateness_us_max", s.lateness_us_max).Number("model_age_ms", s.model_age_ms);
  w.Number("round_trip_us_p50", s.round_trip_us_p50);
  w.Number("round_trip_us_p99", s.round_trip_us_p99);
  w.Number("force_norm_n", s.force_norm_n).Int("ticks", s.ticks);
  w.Int("models_received", s.models_received).Int("models_rejected", s.models_rejected);
  w.Int("force_clamps", s.force_clamps).Int("slew_limits", s.slew_limits);
  w.Int("fades", s.fades).Int("snaps_felt", s.snaps_felt);
  DeviceRoundFields(&w, s);
  return w.EndObject().Take();
}

}  // namespace snapthread::web
