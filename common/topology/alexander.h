// The Alexander polynomial and the determinant of a knot diagram, in exact arithmetic.
#pragma once

#include <cstdint>
#include <vector>

#include "topology/diagram.h"

namespace snapthread::topology {

struct AlexanderResult {
  bool ok = false;               // false: the diagram is not a knot's (Δ(1) != ±1)
  std::int64_t determinant = 0;  // |Δ(-1)|, exact; -1 if it exceeds 2^60
  // Δ(t) coefficients from t^0 up, normalised to Δ(1) = +1 with no factor t (so defined up
  // to t -> 1/t, which the knot's symmetry makes a no-op). Empty when the diagram has too
  // many crossings for the polynomial (the determinant is still exact).
  std::vector<std::int64_t> polynomial;
};

// Wirtinger arcs from the crossings, the Alexander matrix (one row per crossing:
// (1 - t) on the over arc, t and -1 on the arcs coming in and going out under it, swapped
// for a negative crossing), one row and column struck. The determinant is the struck
// matrix's determinant at t = -1 modulo two 61-bit primes (intermediate minors of a
// fraction-free elimination grow like 6^(N/2) and would overflow even __int128 beyond
// ~95 crossings; residues cannot), lifted to the symmetric range and cross-checked. The
// polynomial comes from fraction-free (Bareiss) elimination over Z[t] with __int128
// coefficients, for up to kMaxPolynomialCrossings crossings, dropped on any overflow.
AlexanderResult ComputeAlexander(const Diagram& diagram);

inline constexpr int kMaxPolynomialCrossings = 60;

}  // namespace snapthread::topology
