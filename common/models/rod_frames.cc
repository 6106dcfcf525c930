#include "models/rod_frames.h"

namespace snapthread::rod {
namespace {

// A(s) = sin√s/√s and B(s) = (1 - cos√s)/s with their first two derivatives in s.
struct Coefficients {
  double a, a1, a2, b, b1, b2;
};

Coefficients RodriguesCoefficients(double s) {
  Coefficients c{};
  if (s < 0.1) {
    // A = Σ (-s)^k / (2k+1)!, B = Σ (-s)^k / (2k+2)!; nine terms leave < 1e-20.
    // Term k contributes f s^k, f k s^(k-1), f k (k-1) s^(k-2) to the value and the
    // two derivatives (powers carried along, no pow calls).
    double fa = 1.0, fb = 0.5;  // (-1)^k / (2k+1)!, (-1)^k / (2k+2)!
    double pk = 1.0, pk1 = 0.0, pk2 = 0.0;  // s^k, s^(k-1), s^(k-2) (0 when k is too small)
    for (int k = 0; k < 9; ++k) {
      c.a += fa * pk;
      c.a1 += fa * k * pk1;
      c.a2 += fa * k * (k - 1.0) * pk2;
      c.b += fb * pk;
      c.b1 += fb * k * pk1;
      c.b2 += fb * k * (k - 1.0) * pk2;
      fa /= -(2.0 * k + 2.0) * (2.0 * k + 3.0);
      fb /= -(2.0 * k + 3.0) * (2.0 * k + 4.0);
      pk2 = pk1;
      pk1 = pk;
      pk *= s;
    }
    return c;
  }
  const double th = std::sqrt(s);
  const double cs = std::cos(th);
  c.a = std::sin(th) / th;
  c.b = (1.0 - cs) / s;
  c.a1 = (cs - c.a) / (2.0 * s);
  c.a2 = (-0.5 * c.a - 3.0 * c.a1) / (2.0 * s);
  c.b1 = (0.5 * c.a - c.b) / s;
  c.b2 = (0.5 * c.a1 - 2.0 * c.b1) / s;
  return c;
}

}  // namespace

JetVec RotateJet(const V3& phi, const V3& v) {
  JetVec p;
  for (int k = 0; k < 3; ++k) p.c[k] = Jet::Variable(phi[k], k);
  const Jet s = Dot(p, p);
  const Coefficients co = RodriguesCoefficients(s.v);
  const Jet a = Chain(s, co.a, co.a1, co.a2);
  const Jet b = Chain(s, co.b, co.b1, co.b2);
  const JetVec pv = CrossJ(p, JetVec::Constant(v));
  const JetVec ppv = CrossJ(p, pv);
  return JetVec::Constant(v) + a * pv + b * ppv;
}

}  // namespace snapthread::rod
