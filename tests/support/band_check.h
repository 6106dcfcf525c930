// The fused band assembly (BandAssemblyCapability::EnergyGradientAndBandHessian) against the
// separate calls, for the tests of the models that write E_xx straight into the banded
// factorisation's storage (direct_assembly_test.cc, rod_evaluate_test.cc). Header-only:
// for the test binaries that link the models.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "models/band_assembly_capability.h"
#include "models/model.h"
#include "numeric/types.h"

namespace snapthread::test_support {

// E, E_x and E_xx of the separate calls (Hessian(), Gradient(), Energy(), in that order).
struct SeparateValues {
  double e = 0.0;
  Vec g;
  SparseMatrix h;
};

inline SeparateValues EvaluateSeparately(const Model& m, const Vec& x, const Vec& u) {
  SeparateValues v;
  v.h = m.HessianPattern();
  m.Hessian(x, u, &v.h);
  m.Gradient(x, u, &v.g);
  v.e = m.Energy(x, u);
  return v;
}

// What the fused call wrote into band storage of bandwidth b (row-major, b + 1 slots a
// row), filled with NaN before the call, so that a slot it did not write shows.
struct BandAssembly {
  bool written = false;  // the call's answer: false, the model declined
  std::vector<double> band;
  Vec g;
  double e = 0.0;

  // Not one slot written (what a declining model must leave).
  bool Untouched() const {
    return std::all_of(band.begin(), band.end(), [](double v) { return std::isnan(v); });
  }
};

inline BandAssembly AssembleBand(const Model& m, const Vec& x, const Vec& u, int b) {
  BandAssembly a;
  a.band.assign(static_cast<size_t>(m.NumStates()) * static_cast<size_t>(std::max(b, 0) + 1),
                std::numeric_limits<double>::quiet_NaN());
  const BandAssemblyCapability* assembly = m.band_assembly();  // null: the model writes no band
  a.written = assembly != nullptr && assembly->EnergyGradientAndBandHessian(x, u, &a.g, a.band.data(), b, &a.e);
  return a;
}

// E and E_x of the fused call are the separate calls' to the last bit, every
// lower-triangle entry of E_xx's pattern is at its band slot with Hessian()'s value, and
// every other slot is zero. `what` names the case in the failures.
inline void ExpectBandHoldsSeparateValues(const BandAssembly& a, int b, const SeparateValues& v,
                                          const std::string& what) {
  EXPECT_EQ(std::memcmp(&v.e, &a.e, sizeof v.e), 0) << what << ": E " << v.e << " vs " << a.e;
  ASSERT_EQ(a.g.size(), v.g.size()) << what;
  EXPECT_EQ(std::memcmp(v.g.data(), a.g.data(), sizeof(double) * v.g.size()), 0) << what << ": E_x";
  std::vector<char> in_pattern(a.band.size(), 0);
  for (int j = 0; j < v.h.outerSize(); ++j) {
    for (SparseMatrix::InnerIterator it(v.h, j); it; ++it) {
      if (it.row() < j) continue;
      const size_t slot = static_cast<size_t>(it.row()) * (b + 1) + j - it.row() + b;
      in_pattern[slot] = 1;
      EXPECT_EQ(a.band[slot], it.value()) << what << ": E_xx(" << it.row() << ", " << j << ")";
    }
  }
  for (size_t k = 0; k < a.band.size(); ++k) {
    if (!in_pattern[k]) {
      EXPECT_EQ(a.band[k], 0.0) << what << ": slot " << k << " outside the pattern";
    }
  }
}

}  // namespace snapthread::test_support
