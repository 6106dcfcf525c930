#include "shape_check.h"

#include <cmath>

#include "messages/validate.h"

namespace snapthread::viewer {

bool DecodeShape(const void* data, int size, thread_shape_t* out, std::string* why) {
  if (!messages::DecodeAndValidate(data, size, out, why)) return false;
  if (out->num_nodes < 1) {  // valid on the wire, but there is no thread to draw
    *why = "thread_shape_t without nodes";
    return false;
  }
  // Material frames (the rod): one per edge, each with a unit director d1.
  if (out->num_frames != 0 && out->num_frames != out->num_nodes - 1) {
    *why = "thread_shape_t with " + std::to_string(out->num_frames) + " frames for " +
           std::to_string(out->num_nodes) + " nodes (expected 0 or one per edge)";
    return false;
  }
  for (int j = 0; j < out->num_frames; ++j) {
    const auto& f = out->frames[j];
    const double norm = std::sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
    if (std::abs(norm - 1.0) > 1e-3) {
      *why = "thread_shape_t frame " + std::to_string(j) + ": director d1 of length " +
             std::to_string(norm) + ", expected a unit vector";
      return false;
    }
  }
  return true;
}

bool DecodeSolverStatus(const void* data, int size, solver_status_t* out, std::string* why) {
  return messages::DecodeAndValidate(data, size, out, why);
}

}  // namespace snapthread::viewer
