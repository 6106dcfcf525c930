#include <cmath>
#include <stdexcept>
#include <string>

#include "models/models.h"

namespace snapthread {

bool ModelParams::IsValid(std::string* error) const {
  auto fail = [&](const std::string& m) {
    if (error) *error = m;
    return false;
  };
  if (model != "zeeman" && model != "cusp" && model != "curve2d" && model != "thread3d") {
    return fail("model: expected one of zeeman, cusp, curve2d, thread3d, got '" + model + "'");
  }
  if (model == "curve2d" || model == "thread3d") {
    const int min_n = (model == "thread3d" && grip_direction) ? 3 : 2;
    if (n < min_n) return fail("params.n: expected an integer >= " + std::to_string(min_n) +
                               ", got " + std::to_string(n));
    if (!(segment_length > 0.0) || !std::isfinite(segment_length))
      return fail("params.segment_length: expected a finite number > 0");
    if (!(bending > 0.0) || !std::isfinite(bending))
      return fail("params.bending: expected a finite number > 0 (beta)");
    if (!(stretching > 0.0) || !std::isfinite(stretching))
      return fail("params.stretching: expected a finite number > 0 (gamma)");
    if (!std::isfinite(reference_bend)) return fail("params.reference_bend: expected a finite number");
  }
  if (grip_direction && model != "thread3d")
    return fail("params.grip_direction: only thread3d has a grip direction");
  return true;
}

std::unique_ptr<Model> MakeModel(const ModelParams& params) {
  std::string error;
  if (!params.IsValid(&error)) throw std::invalid_argument(error);
  if (params.model == "zeeman") return MakeZeemanModel();
  if (params.model == "cusp") return MakeCuspModel();
  if (params.model == "curve2d") return MakeCurve2dModel(params);
  return MakeThread3dModel(params);
}

}  // namespace snapthread
