#include "topology/simplify.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <unordered_map>

#include <Eigen/Geometry>

namespace snapthread::topology {
namespace {

constexpr double kRelTol = 1e-9;
// An edge whose box covers more cells than this goes to the list every query scans.
constexpr std::int64_t kMaxCellsPerEdge = 64;

struct Box {
  Eigen::Vector3d lo, hi;
};

Box BoxOf(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return {a.cwiseMin(b), a.cwiseMax(b)};
}

// Do coplanar segments pq and rs (plane normal n) meet, within tol?
bool SegmentsMeetInPlane(const Eigen::Vector3d& p, const Eigen::Vector3d& q,
                         const Eigen::Vector3d& r, const Eigen::Vector3d& s,
                         const Eigen::Vector3d& n, double tol) {
  // Signed areas in the plane: each segment's ends on opposite sides of the other's line.
  auto side = [&](const Eigen::Vector3d& o, const Eigen::Vector3d& d, const Eigen::Vector3d& x) {
    return d.cross(x - o).dot(n);
  };
  const Eigen::Vector3d pq = q - p, rs = s - r;
  const double slack_pq = tol * pq.norm(), slack_rs = tol * rs.norm();
  const double r_side = side(p, pq, r), s_side = side(p, pq, s);
  const double p_side = side(r, rs, p), q_side = side(r, rs, q);
  return !((r_side > slack_pq && s_side > slack_pq) || (r_side < -slack_pq && s_side < -slack_pq) ||
           (p_side > slack_rs && q_side > slack_rs) || (p_side < -slack_rs && q_side < -slack_rs));
}

// Does segment pq meet triangle abc (grazing within tol counts)? Möller–Trumbore.
bool SegmentMeetsTriangle(const Eigen::Vector3d& p, const Eigen::Vector3d& q,
                          const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                          const Eigen::Vector3d& c, double scale) {
  const Eigen::Vector3d e1 = b - a, e2 = c - a, dir = q - p;
  const Eigen::Vector3d normal = e1.cross(e2);
  const double area2 = normal.norm();
  if (area2 <= 1e-24 * scale * scale) return false;  // degenerate triangle: sweeps nothing
  const Eigen::Vector3d n = normal / area2;
  const double dp = (p - a).dot(n), dq = (q - a).dot(n);
  const double tol = kRelTol * scale;
  if (dp > tol && dq > tol) return false;
  if (dp < -tol && dq < -tol) return false;
  // The segment reaches the plane's slab: find where it is nearest the plane and check
  // that point (or, lying in the plane, both ends and the middle) against the triangle.
  auto inside = [&](const Eigen::Vector3d& x) {
    const Eigen::Vector3d r = x - a;
    const double u = r.cross(e2).dot(n) / area2;  // weight of b
    const double w = e1.cross(r).dot(n) / area2;  // weight of c
    const double slack = kRelTol * 10.0;
    return u >= -slack && w >= -slack && u + w <= 1.0 + slack;
  };
  if (std::abs(dp - dq) <= tol) {
    // Lying in the plane: blocked if an end is inside or the segment meets an edge.
    if (inside(p) || inside(q)) return true;
    const std::array<const Eigen::Vector3d*, 3> v = {&a, &b, &c};
    for (int k = 0; k < 3; ++k) {
      if (SegmentsMeetInPlane(p, q, *v[k], *v[(k + 1) % 3], n, tol)) return true;
    }
    return false;
  }
  const double t = std::clamp(dp / (dp - dq), 0.0, 1.0);
  return inside(p + t * dir);
}

class EdgeGrid {
 public:
  EdgeGrid(const Box& bounds, double cell) : lo_(bounds.lo), cell_(cell) {}

  void Insert(int edge, const Box& box) {
    const Eigen::Array3i a = Index(box.lo), b = Index(box.hi);
    const std::int64_t cells = std::int64_t{b.x() - a.x() + 1} * (b.y() - a.y() + 1) *
                               (b.z() - a.z() + 1);
    if (cells > kMaxCellsPerEdge) {
      long_edges_.push_back(edge);
      return;
    }
    for (int i = a.x(); i <= b.x(); ++i)
      for (int j = a.y(); j <= b.y(); ++j)
        for (int k = a.z(); k <= b.z(); ++k) cells_[Key(i, j, k)].push_back(edge);
  }

  // Calls f(edge) for every edge filed under a cell the box touches (repeats possible),
  // or returns false when the box covers too many cells to enumerate.
  template <class F>
  bool Visit(const Box& box, F&& f) const {
    const Eigen::Array3i a = Index(box.lo), b = Index(box.hi);
    const std::int64_t cells = std::int64_t{b.x() - a.x() + 1} * (b.y() - a.y() + 1) *
                               (b.z() - a.z() + 1);
    if (cells > 8 * kMaxCellsPerEdge) return false;
    for (int e : long_edges_) f(e);
    for (int i = a.x(); i <= b.x(); ++i)
      for (int j = a.y(); j <= b.y(); ++j)
        for (int k = a.z(); k <= b.z(); ++k) {
          auto it = cells_.find(Key(i, j, k));
          if (it == cells_.end()) continue;
          for (int e : it->second) f(e);
        }
    return true;
  }

 private:
  Eigen::Array3i Index(const Eigen::Vector3d& x) const {
    return ((x - lo_).array() / cell_).floor().cast<int>();
  }
  static std::int64_t Key(int i, int j, int k) {
    return (std::int64_t{i} * 73856093) ^ (std::int64_t{j} * 19349663) ^
           (std::int64_t{k} * 83492791) ^ (std::int64_t{i} << 42);
  }
  Eigen::Vector3d lo_;
  double cell_;
  std::unordered_map<std::int64_t, std::vector<int>> cells_;
  std::vector<int> long_edges_;
};

}  // namespace

void SimplifyClosedPolygon(std::vector<Eigen::Vector3d>& polygon) {
  const int n = static_cast<int>(polygon.size());
  if (n <= 3) return;
  // Edge s runs from vertex s to next[s]; removing v rewires edge prev[v] and kills edge v.
  std::vector<int> next(n), prev(n);
  std::vector<char> alive(n, 1);
  for (int i = 0; i < n; ++i) {
    next[i] = (i + 1) % n;
    prev[i] = (i + n - 1) % n;
  }
  Box bounds{polygon[0], polygon[0]};
  for (const auto& p : polygon) bounds = {bounds.lo.cwiseMin(p), bounds.hi.cwiseMax(p)};
  const double scale = std::max((bounds.hi - bounds.lo).norm(), 1e-300);
  std::vector<int> stamp(n, -1);
  int count = n, query = 0;
  for (bool removed = true; removed && count > 3;) {
    removed = false;
    // Cells of about two typical edges: the median, since the closure's few long edges
    // would inflate a mean (they go to the grid's scan-always list instead).
    std::vector<double> lengths;
    lengths.reserve(count);
    for (int s = 0; s < n; ++s)
      if (alive[s]) lengths.push_back((polygon[next[s]] - polygon[s]).norm());
    std::nth_element(lengths.begin(), lengths.begin() + count / 2, lengths.end());
    const double cell = std::max(2.0 * lengths[count / 2], 1e-9 * scale);
    EdgeGrid grid(bounds, cell);
    for (int s = 0; s < n; ++s)
      if (alive[s]) grid.Insert(s, BoxOf(polygon[s], polygon[next[s]]));
    // A vertex whose neighbour went this pass waits for the next one: chains of removals
    // would grow one triangle across the whole curve, and every query with it.
    std::vector<char> touched(n, 0);
    for (int v = 0; v < n && count > 3; ++v) {
      if (!alive[v] || touched[v]) continue;
      const int a = prev[v], c = next[v];
      const Eigen::Vector3d &pa = polygon[a], &pv = polygon[v], &pc = polygon[c];
      Box tri = BoxOf(pa, pv);
      tri = {tri.lo.cwiseMin(pc), tri.hi.cwiseMax(pc)};
      ++query;
      bool blocked = false;
      auto test = [&](int s) {
        if (blocked || !alive[s] || stamp[s] == query) return;
        stamp[s] = query;
        const Box e = BoxOf(polygon[s], polygon[next[s]]);
        if ((e.lo.array() > tri.hi.array()).any() || (e.hi.array() < tri.lo.array()).any())
          return;
        // Edges sharing a vertex with the triangle meet it only there.
        if (s == prev[a] || s == a || s == v || s == c) return;
        blocked = SegmentMeetsTriangle(polygon[s], polygon[next[s]], pa, pv, pc, scale);
      };
      if (!grid.Visit(tri, test)) {
        for (int s = 0; s < n && !blocked; ++s) test(s);
      }
      if (blocked) continue;
      alive[v] = 0;
      touched[a] = touched[c] = 1;
      next[a] = c;
      prev[c] = a;
      --count;
      removed = true;
      grid.Insert(a, BoxOf(pa, pc));
    }
  }
  std::vector<Eigen::Vector3d> out;
  out.reserve(count);
  int start = 0;
  while (!alive[start]) ++start;
  int v = start;
  do {
    out.push_back(polygon[v]);
    v = next[v];
  } while (v != start);
  polygon.swap(out);
}

}  // namespace snapthread::topology
