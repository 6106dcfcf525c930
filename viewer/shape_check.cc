#include "shape_check.h"

#include "messages/validate.h"

namespace snapthread::viewer {

bool DecodeShape(const void* data, int size, thread_shape_t* out, std::string* why) {
  if (!transport::DecodeAndValidate(data, size, out, why)) return false;
  if (out->num_nodes < 1) {  // valid on the wire, but there is no thread to draw
    *why = "thread_shape_t without nodes";
    return false;
  }
  return true;
}

bool DecodeSolverStatus(const void* data, int size, solver_status_t* out, std::string* why) {
  return transport::DecodeAndValidate(data, size, out, why);
}

}  // namespace snapthread::viewer
