#include "limiter.h"

#include <cmath>

namespace snapthread::device {

LimitVerdict VectorLimiter::Apply(double v[3]) {
  LimitVerdict l;
  const double n = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  if (!std::isfinite(n)) {
    // An overflow upstream (absurd but finite inputs): aim at zero through the slew limit.
    v[0] = v[1] = v[2] = 0.0;
    l.clamped = true;
  } else if (n > max_norm_) {
    const double s = max_norm_ / n;
    for (int k = 0; k < 3; ++k) v[k] *= s;
    l.clamped = true;
  }
  double d[3], dn2 = 0.0;
  for (int k = 0; k < 3; ++k) {
    d[k] = v[k] - last_[k];
    dn2 += d[k] * d[k];
  }
  if (dn2 > max_step_ * max_step_) {
    const double s = max_step_ / std::sqrt(dn2);
    for (int k = 0; k < 3; ++k) v[k] = last_[k] + s * d[k];
    l.slew_limited = true;
  }
  // Last line of defence: never a non-finite output.
  if (!std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2])) {
    v[0] = v[1] = v[2] = 0.0;
    l.nonfinite = true;
  }
  for (int k = 0; k < 3; ++k) last_[k] = v[k];
  return l;
}

}  // namespace snapthread::device
