#include "messages/validate.h"

#include <cmath>
#include <cstdint>
#include <cstring>

namespace snapthread::transport {
namespace {

bool Fail(std::string* why, const std::string& text) {
  if (why) *why = text;
  return false;
}

bool Finite(const double* v, int n) {
  for (int i = 0; i < n; ++i) {
    if (!std::isfinite(v[i])) return false;
  }
  return true;
}

bool CheckFinite(const double* v, int n, const char* field, std::string* why) {
  if (Finite(v, n)) return true;
  return Fail(why, std::string(field) + " is not finite");
}

bool CheckString(const std::string& s, const char* field, std::string* why) {
  if (s.size() <= kMaxStringBytes) return true;
  return Fail(why, std::string(field) + " longer than " + std::to_string(kMaxStringBytes) +
                       " bytes");
}

bool CheckStatus(int8_t status, std::string* why) {
  if (status >= force_model_t::STATUS_REGULAR && status <= force_model_t::STATUS_INVALID) {
    return true;
  }
  return Fail(why, "status " + std::to_string(status) + " is not one of STATUS_*");
}

// Big-endian reads of LCM's wire format (lcm_coretypes.h).
bool ReadI32(const uint8_t* p, int size, int* pos, int32_t* out) {
  if (*pos < 0 || size - *pos < 4) return false;
  uint32_t v = 0;
  for (int i = 0; i < 4; ++i) v = (v << 8) | p[*pos + i];
  *pos += 4;
  std::memcpy(out, &v, 4);
  return true;
}

bool SkipString(const uint8_t* p, int size, int* pos) {
  int32_t len = 0;
  if (!ReadI32(p, size, pos, &len)) return false;
  if (len < 1 || len > size - *pos) return false;  // includes the terminating NUL
  *pos += len;
  return true;
}

// Checks `count` consecutive strings starting at byte `pos`; advances pos past them.
bool CheckStrings(const void* data, int size, int* pos, int count, const char* type,
                  std::string* why) {
  const auto* p = static_cast<const uint8_t*>(data);
  if (size < *pos) return Fail(why, std::string(type) + " truncated");
  for (int i = 0; i < count; ++i) {
    if (!SkipString(p, size, pos)) {
      return Fail(why, std::string(type) + ": malformed string length");
    }
  }
  return true;
}

}  // namespace

// Offsets: 8-byte type hash, then the fields in .lcm order (lcmtypes/*.lcm).
template <>
bool PreDecodeCheck<force_model_t>(const void*, int, std::string*) {
  return true;  // fixed size: the generated decoder checks every read against the length
}

template <>
bool PreDecodeCheck<device_state_t>(const void* data, int size, std::string* why) {
  int pos = 24;  // hash, utime, seq | device_id
  return CheckStrings(data, size, &pos, 1, "device_state_t", why);
}

template <>
bool PreDecodeCheck<solver_status_t>(const void* data, int size, std::string* why) {
  int pos = 24;  // hash, utime, seq | scene, method
  return CheckStrings(data, size, &pos, 2, "solver_status_t", why);
}

template <>
bool PreDecodeCheck<device_status_t>(const void* data, int size, std::string* why) {
  int pos = 24;  // hash, utime, seq | device_id
  return CheckStrings(data, size, &pos, 1, "device_status_t", why);
}

template <>
bool PreDecodeCheck<command_t>(const void* data, int size, std::string* why) {
  int pos = 17;  // hash, utime, command (int8) | argument
  return CheckStrings(data, size, &pos, 1, "command_t", why);
}

template <>
bool PreDecodeCheck<thread_shape_t>(const void* data, int size, std::string* why) {
  int pos = 24;  // hash, utime, seq | scene, model | num_nodes, positions...
  if (!CheckStrings(data, size, &pos, 2, "thread_shape_t", why)) return false;
  const auto* p = static_cast<const uint8_t*>(data);
  int32_t num_nodes = 0;
  if (!ReadI32(p, size, &pos, &num_nodes)) return Fail(why, "thread_shape_t truncated");
  if (num_nodes < 0 || num_nodes > kMaxShapeNodes) {
    return Fail(why, "thread_shape_t: num_nodes " + std::to_string(num_nodes) +
                         " outside [0, " + std::to_string(kMaxShapeNodes) + "]");
  }
  if (static_cast<int64_t>(num_nodes) * 24 > size - pos) {
    return Fail(why, "thread_shape_t: buffer too short for num_nodes " +
                         std::to_string(num_nodes));
  }
  return true;
}

bool Validate(const device_state_t& msg, std::string* why) {
  if (!CheckString(msg.device_id, "device_id", why)) return false;
  if (!CheckFinite(msg.position, 3, "position", why)) return false;
  if (!CheckFinite(msg.orientation, 4, "orientation", why)) return false;
  double n2 = 0.0;
  for (double q : msg.orientation) n2 += q * q;
  const double n = std::sqrt(n2);
  if (n < kMinQuaternionNorm || n > kMaxQuaternionNorm) {
    return Fail(why, "orientation quaternion norm " + std::to_string(n) + " outside [0.5, 2]");
  }
  return true;
}

bool Validate(const force_model_t& msg, std::string* why) {
  if (!CheckStatus(msg.status, why)) return false;
  if (!CheckFinite(msg.u0, 3, "u0", why)) return false;
  if (!CheckFinite(msg.f0, 3, "f0", why)) return false;
  if (!CheckFinite(&msg.K[0][0], 9, "K", why)) return false;
  if (msg.has_torque != 0 && msg.has_torque != 1) {
    return Fail(why, "has_torque must be 0 or 1");
  }
  if (!CheckFinite(msg.torque0, 3, "torque0", why)) return false;
  if (!CheckFinite(&msg.residual, 1, "residual", why)) return false;
  if (msg.iterations < 0) return Fail(why, "iterations negative");
  if (msg.solve_us < 0) return Fail(why, "solve_us negative");
  return true;
}

bool Validate(const thread_shape_t& msg, std::string* why) {
  if (!CheckString(msg.scene, "scene", why) || !CheckString(msg.model, "model", why)) {
    return false;
  }
  if (msg.num_nodes < 0 || msg.num_nodes > kMaxShapeNodes) {
    return Fail(why, "num_nodes " + std::to_string(msg.num_nodes) + " outside [0, " +
                         std::to_string(kMaxShapeNodes) + "]");
  }
  if (msg.positions.size() != static_cast<size_t>(msg.num_nodes)) {
    return Fail(why, "positions has " + std::to_string(msg.positions.size()) +
                         " rows, num_nodes says " + std::to_string(msg.num_nodes));
  }
  for (size_t i = 0; i < msg.positions.size(); ++i) {
    const auto& row = msg.positions[i];
    if (row.size() != 3) {
      return Fail(why, "positions row " + std::to_string(i) + " has " +
                           std::to_string(row.size()) + " entries, expected 3");
    }
    if (!Finite(row.data(), 3)) {
      return Fail(why, "positions row " + std::to_string(i) + " is not finite");
    }
  }
  if (!CheckFinite(msg.grasp, 3, "grasp", why)) return false;
  if (!CheckFinite(msg.grip_direction, 3, "grip_direction", why)) return false;
  if (!CheckFinite(msg.force, 3, "force", why)) return false;
  if (!CheckFinite(msg.force_newtons, 3, "force_newtons", why)) return false;
  if (!CheckStatus(msg.status, why)) return false;
  return true;
}

bool Validate(const solver_status_t& msg, std::string* why) {
  if (!CheckString(msg.scene, "scene", why) || !CheckString(msg.method, "method", why)) {
    return false;
  }
  if (!CheckFinite(&msg.residual, 1, "residual", why)) return false;
  if (!CheckFinite(&msg.lambda_min, 1, "lambda_min", why)) return false;
  if (!CheckFinite(&msg.update_rate_hz, 1, "update_rate_hz", why)) return false;
  if (!CheckFinite(&msg.solve_us_p50, 1, "solve_us_p50", why)) return false;
  if (!CheckFinite(&msg.solve_us_p99, 1, "solve_us_p99", why)) return false;
  if (!CheckStatus(msg.status, why)) return false;
  return true;
}

bool Validate(const device_status_t& msg, std::string* why) {
  if (!CheckString(msg.device_id, "device_id", why)) return false;
  const double values[] = {msg.tick_rate_hz,     msg.lateness_us_p50,   msg.lateness_us_p99,
                           msg.lateness_us_max,  msg.model_age_ms,      msg.round_trip_us_p50,
                           msg.round_trip_us_p99, msg.force_norm_n};
  if (!CheckFinite(values, 8, "a statistic", why)) return false;
  return true;
}

bool Validate(const command_t& msg, std::string* why) {
  if (msg.command != command_t::RESET && msg.command != command_t::LOAD_SCENE &&
      msg.command != command_t::SET_METHOD) {
    return Fail(why, "unknown command " + std::to_string(msg.command));
  }
  if (!CheckString(msg.argument, "argument", why)) return false;
  return true;
}

}  // namespace snapthread::transport
