#include "contact/ccd.h"

#include <algorithm>
#include <cmath>

#include "contact/segment_distance.h"

namespace snapthread::contact {

double CapsuleCcd(const V3& a0, const V3& a1, const V3& b0, const V3& b1, const V3& da0,
                  const V3& da1, const V3& db0, const V3& db1, double contact_distance,
                  double keep, double t_max, int max_iterations) {
  const V3 mean = 0.25 * (da0 + da1 + db0 + db1);
  V3 p[4] = {da0 - mean, da1 - mean, db0 - mean, db1 - mean};
  const double lp = std::max(p[0].norm(), p[1].norm()) + std::max(p[2].norm(), p[3].norm());
  V3 x[4] = {a0, a1, b0, b1};
  auto gap = [&] {
    return std::sqrt(ClosestPoints(x[0], x[1], x[2], x[3]).distance_sq) - contact_distance;
  };
  const double gap0 = gap();
  if (!(gap0 > 0.0)) return 0.0;
  if (lp == 0.0) return t_max;  // a common translation: no distance changes
  const double target = keep * gap0;
  double t = 0.0;
  double step = (1.0 - keep) * gap0 / lp;  // closes at most (1 - keep) of the gap
  for (int it = 0; it < max_iterations; ++it) {
    for (int k = 0; k < 4; ++k) x[k] += step * p[k];
    const double g = gap();
    if (t > 0.0 && g < target) return t;
    t += step;
    if (t >= t_max) return t_max;
    step = 0.9 * g / lp;  // closes at most 0.9 of the gap now
  }
  return t;
}

}  // namespace snapthread::contact
