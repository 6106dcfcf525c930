#include "topology/diagram.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include <Eigen/Geometry>

namespace snapthread::topology {
namespace {

constexpr double kRelTol = 1e-9;

double Cross2(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a.x() * b.y() - a.y() * b.x();
}

}  // namespace

Diagram ProjectDiagram(std::span<const Eigen::Vector3d> polygon,
                       const Eigen::Vector3d& direction) {
  Diagram d;
  const int n = static_cast<int>(polygon.size());
  d.num_edges = n;
  if (n < 3) return d;
  // Right-handed frame (e1, e2, view): the viewer sits at +view, height = x . view.
  const Eigen::Vector3d view = direction.normalized();
  const Eigen::Vector3d e1 = view.unitOrthogonal();
  const Eigen::Vector3d e2 = view.cross(e1);
  std::vector<Eigen::Vector2d> xy(n);
  std::vector<double> height(n);
  double lo = INFINITY, hi = -INFINITY;
  for (int i = 0; i < n; ++i) {
    xy[i] = {polygon[i].dot(e1), polygon[i].dot(e2)};
    height[i] = polygon[i].dot(view);
    lo = std::min({lo, xy[i].x(), xy[i].y(), height[i]});
    hi = std::max({hi, xy[i].x(), xy[i].y(), height[i]});
  }
  const double scale = std::max(hi - lo, 1e-300);
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  auto xmin = [&](int i) { return std::min(xy[i].x(), xy[(i + 1) % n].x()); };
  auto xmax = [&](int i) { return std::max(xy[i].x(), xy[(i + 1) % n].x()); };
  std::sort(order.begin(), order.end(), [&](int a, int b) { return xmin(a) < xmin(b); });
  for (int oi = 0; oi < n; ++oi) {
    const int i = order[oi];
    const Eigen::Vector2d p = xy[i], r = xy[(i + 1) % n] - p;
    for (int oj = oi + 1; oj < n && xmin(order[oj]) <= xmax(i); ++oj) {
      const int j = order[oj];
      const bool adjacent = (j == (i + 1) % n) || (i == (j + 1) % n);
      const Eigen::Vector2d q = xy[j], u = xy[(j + 1) % n] - q;
      if (std::max(p.y(), p.y() + r.y()) < std::min(q.y(), q.y() + u.y()) ||
          std::max(q.y(), q.y() + u.y()) < std::min(p.y(), p.y() + r.y()))
        continue;
      const double denom = Cross2(r, u);
      if (std::abs(denom) <= kRelTol * r.norm() * u.norm()) {
        // Parallel: a problem only if the two lie on one line and overlap.
        if (std::abs(Cross2(q - p, r)) <= kRelTol * scale * r.norm()) {
          const double rr = std::max(r.squaredNorm(), 1e-300);
          const double t0 = (q - p).dot(r) / rr, t1 = (q + u - p).dot(r) / rr;
          if (std::max(t0, t1) > kRelTol && std::min(t0, t1) < 1.0 - kRelTol &&
              !(adjacent && std::min(t0, t1) >= 1.0 - kRelTol))
            d.generic = false;
        }
        continue;
      }
      if (adjacent) continue;  // two non-parallel neighbours meet only at their vertex
      const double s = Cross2(q - p, u) / denom;
      const double t = Cross2(q - p, r) / denom;
      if (s < -kRelTol || s > 1.0 + kRelTol || t < -kRelTol || t > 1.0 + kRelTol) continue;
      if (s < kRelTol || s > 1.0 - kRelTol || t < kRelTol || t > 1.0 - kRelTol) {
        d.generic = false;  // the crossing falls on a vertex
        continue;
      }
      const double hi_i = height[i] + s * (height[(i + 1) % n] - height[i]);
      const double hj = height[j] + t * (height[(j + 1) % n] - height[j]);
      if (std::abs(hi_i - hj) <= kRelTol * scale) {
        d.generic = false;  // the strands touch (or nearly) in space
        continue;
      }
      Crossing c;
      const bool i_over = hi_i > hj;
      c.over_edge = i_over ? i : j;
      c.over_param = i_over ? s : t;
      c.under_edge = i_over ? j : i;
      c.under_param = i_over ? t : s;
      const double turn = i_over ? Cross2(r, u) : Cross2(u, r);
      c.sign = turn > 0 ? 1 : -1;
      d.crossings.push_back(c);
    }
  }
  return d;
}

}  // namespace snapthread::topology
