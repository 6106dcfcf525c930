#include "models/rod_params.h"

#include <cmath>

namespace snapthread {

using M3 = Eigen::Matrix3d;

bool RodParams::IsValid(std::string* error) const {
  auto fail = [&](const std::string& why) {
    if (error != nullptr) *error = "rod: " + why;
    return false;
  };
  if (n < 3) return fail("n must be at least 3 (the clamp and the grasp hold one edge each)");
  if (free_start && n < 5) return fail("n must be at least 5 without a clamp (two grasps)");
  if (!(length > 0.0) || !std::isfinite(length)) return fail("length must be positive");
  const double stiffnesses[] = {stretch_stiffness, bend_stiffness, bend_stiffness_2,
                                twist_stiffness};
  for (double s : stiffnesses) {
    if (!(s > 0.0) || !std::isfinite(s)) return fail("stiffnesses must be positive and finite");
  }
  if (!std::isfinite(natural_curvature) || !std::isfinite(natural_curvature_2))
    return fail("natural curvature must be finite");
  if (!(radius >= 0.0) || !std::isfinite(radius)) return fail("radius must be >= 0");
  if (!clamp_position.allFinite()) return fail("clamp position must be finite");
  for (const M3* r : {&clamp_rotation, &grasp_rotation}) {
    if (!r->allFinite() || ((*r).transpose() * (*r) - M3::Identity()).norm() > 1e-9 ||
        r->determinant() < 0.0) {
      return fail("clamp and grasp rotations must be proper rotation matrices");
    }
  }
  return true;
}

}  // namespace snapthread
