#include "topology/identify_knot.h"

#include <cmath>

#include "topology/alexander.h"
#include "topology/closure.h"
#include "topology/diagram.h"
#include "topology/knot_table.h"
#include "topology/simplify.h"

namespace snapthread::topology {
namespace {

std::uint64_t SplitMix(std::uint64_t& state) {
  std::uint64_t z = (state += 0x9e3779b97f4a7c15ULL);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

// A pseudo-random unit vector, uniform on the sphere.
Eigen::Vector3d RandomDirection(std::uint64_t& state) {
  const double u = static_cast<double>(SplitMix(state) >> 11) * 0x1.0p-53;
  const double v = static_cast<double>(SplitMix(state) >> 11) * 0x1.0p-53;
  const double z = 2.0 * u - 1.0, phi = 2.0 * M_PI * v;
  const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
  return {r * std::cos(phi), r * std::sin(phi), z};
}

}  // namespace

KnotInfo IdentifyClosedKnot(std::span<const Eigen::Vector3d> loop, const KnotOptions& options) {
  KnotInfo info;
  for (const auto& p : loop) {
    if (!p.allFinite()) {
      info.error = "a node is not finite";
      return info;
    }
  }
  if (loop.size() < 3) {
    info.error = "fewer than three vertices";
    return info;
  }
  std::vector<Eigen::Vector3d> polygon(loop.begin(), loop.end());
  if (options.simplify) SimplifyClosedPolygon(polygon);
  info.vertices = static_cast<int>(polygon.size());
  struct Answer {
    AlexanderResult result;
    int crossings;
    int votes;
  };
  std::vector<Answer> answers;
  std::uint64_t state = options.seed;
  int generic = 0;
  for (int k = 0; k < options.max_directions && generic < options.projections; ++k) {
    const Diagram d = ProjectDiagram(polygon, RandomDirection(state));
    if (!d.generic) continue;
    const AlexanderResult r = ComputeAlexander(d);
    if (!r.ok) continue;
    ++generic;
    bool found = false;
    for (Answer& a : answers) {
      if (a.result.determinant == r.determinant && a.result.polynomial == r.polynomial) {
        ++a.votes;
        found = true;
      }
    }
    if (!found) answers.push_back({r, static_cast<int>(d.crossings.size()), 1});
  }
  if (answers.empty()) {
    info.error = "no generic projection among " + std::to_string(options.max_directions);
    return info;
  }
  const Answer* best = &answers[0];
  for (const Answer& a : answers)
    if (a.votes > best->votes) best = &a;
  info.ok = true;
  info.determinant = best->result.determinant;
  info.alexander = best->result.polynomial;
  info.crossings = best->crossings;
  info.agreeing = best->votes;
  info.name = KnotName(info.alexander, info.determinant);
  return info;
}

KnotInfo IdentifyKnot(std::span<const Eigen::Vector3d> nodes, const KnotOptions& options) {
  if (nodes.size() < 2) {
    KnotInfo info;
    info.error = "fewer than two nodes";
    return info;
  }
  const std::vector<Eigen::Vector3d> loop = CloseFarAway(nodes);
  if (loop.size() < 3) {
    // Two nodes and one far point at most: a straight piece, unknotted.
    KnotInfo info;
    info.ok = true;
    info.name = "unknot";
    info.determinant = 1;
    info.alexander = {1};
    return info;
  }
  return IdentifyClosedKnot(loop, options);
}

KnotInfo IdentifyKnotXyz(std::span<const double> xyz, const KnotOptions& options) {
  if (xyz.size() % 3 != 0) {
    KnotInfo info;
    info.error = "coordinate count is not a multiple of 3";
    return info;
  }
  std::vector<Eigen::Vector3d> nodes(xyz.size() / 3);
  for (std::size_t i = 0; i < nodes.size(); ++i)
    nodes[i] = {xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]};
  return IdentifyKnot(nodes, options);
}

}  // namespace snapthread::topology
