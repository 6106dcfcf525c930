// Knot identification of a rod's or thread's nodes: the room's entry point.
//
//   std::vector<Eigen::Vector3d> nodes = ...;  // open polyline
//   topology::KnotInfo k = topology::IdentifyKnot(nodes);
//   if (k.ok && k.name == "trefoil") ...        // k.determinant == 3
//
// Steps: CloseFarAway (closure.h), SimplifyClosedPolygon (simplify.h, an isotopy),
// ProjectDiagram along generic directions (diagram.h), ComputeAlexander (alexander.h),
// KnotName (knot_table.h). Exact integer arithmetic throughout the invariant; the geometry
// decides only which side of each crossing is over, and projections where that is close
// (relative 1e-9) are rejected. Allocates: not for the 1 kHz thread.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace snapthread::topology {

struct KnotOptions {
  // Generic projections to take; the answer is the one most of them give (they agree
  // unless a crossing's over/under is decided by rounding).
  int projections = 3;
  // Directions tried before giving up (non-generic ones are skipped).
  int max_directions = 16;
  // Shrink the closed polygon first (simplify.h): fewer crossings, same knot.
  bool simplify = true;
  std::uint64_t seed = 0x5eed;  // of the pseudo-random directions (deterministic)
};

struct KnotInfo {
  bool ok = false;         // false: no generic projection found, or bad input (see error)
  std::string name;        // "unknot", "trefoil", "figure-eight", ..., "unknown (det D)"
  std::int64_t determinant = 0;     // |Δ(-1)|; -1 if above 2^60
  std::vector<std::int64_t> alexander;  // Δ(t) from t^0, Δ(1) = 1; empty if not computed
  int crossings = 0;       // in the projection used (after simplification)
  int vertices = 0;        // of the closed, simplified polygon
  int agreeing = 0;        // projections that gave this answer
  std::string error;
};

// `nodes` is an open polyline (closed far away first, closure.h).
KnotInfo IdentifyKnot(std::span<const Eigen::Vector3d> nodes, const KnotOptions& options = {});
// Same, from packed coordinates x0 y0 z0 x1 ... (size a multiple of 3).
KnotInfo IdentifyKnotXyz(std::span<const double> xyz, const KnotOptions& options = {});
// `loop` is already closed: its last vertex joins its first.
KnotInfo IdentifyClosedKnot(std::span<const Eigen::Vector3d> loop,
                            const KnotOptions& options = {});

}  // namespace snapthread::topology
