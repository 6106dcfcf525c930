// E, E_x and E_xx with E_xx written straight into band storage instead of a compressed
// matrix: the solvers' banded factorisation then skips the copy from one. Model::
// band_assembly() gives it, null for a model that cannot (zeeman and cusp: one state).
#pragma once

#include "numeric/types.h"

namespace snapthread {

class BandAssemblyCapability {
 public:
  virtual ~BandAssemblyCapability() = default;

  // E(x, u) into *energy, E_x into *g and E_xx into the lower band of half-bandwidth
  // `bandwidth` (linalg/banded_ldlt.h's layout, A(i, j), i >= j, at
  // band[i (bandwidth + 1) + j - i + bandwidth]; every other slot of the NumStates()
  // (bandwidth + 1) array is set to 0): the values Energy(), Gradient() and Hessian() give
  // (to the last bit, but for the sign of a zero). Returns false, writing nothing, where
  // the model cannot at this call: self-contact on (its pairs go through the compressed
  // matrix), or another bandwidth than HessianBandwidth().
  virtual bool EnergyGradientAndBandHessian(const Vec& x, const Vec& u, Vec* g, double* band, int bandwidth,
                                            double* energy) const = 0;
};

}  // namespace snapthread
