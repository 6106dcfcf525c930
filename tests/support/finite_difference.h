// Central finite differences for the derivative tests: of any function of a vector, and
// the five derivatives a Model reports (E_x, E_xx, E_u, E_xu, E_uu), each taken from the
// next lower one the model computes. Header-only: for the test binaries that link the
// models (common/models).
//
// A central difference with step h has truncation error O(h²) and round-off about
// eps |f| / h: with h ~ 1e-6 both stay near 1e-9 relative, so a tolerance of 1e-6 passes
// with margin while any wrong term (a factor, a sign, a transpose) is off by O(1).
#pragma once

#include <algorithm>

#include "models/model.h"
#include "numeric/types.h"

namespace snapthread::test_support {

// (f(v + h e_i) - f(v - h e_i)) / 2h for each coordinate i of v: the gradient of a scalar
// f, entry i.
template <class F>
Vec CentralGradient(const F& f, const Vec& v, double h) {
  Vec out(v.size());
  for (int i = 0; i < v.size(); ++i) {
    Vec plus = v, minus = v;
    plus[i] += h;
    minus[i] -= h;
    out[i] = (f(plus) - f(minus)) / (2.0 * h);
  }
  return out;
}

// The same for a vector-valued f (returning a Vec): the Jacobian, column i.
template <class F>
Mat CentralJacobian(const F& f, const Vec& v, double h) {
  Mat out;
  for (int i = 0; i < v.size(); ++i) {
    Vec plus = v, minus = v;
    plus[i] += h;
    minus[i] -= h;
    const Vec column = (f(plus) - f(minus)) / (2.0 * h);
    if (i == 0) out.resize(column.size(), v.size());
    out.col(i) = column;
  }
  return out;
}

// A model's first and second derivatives at one (x, u).
struct ModelDerivatives {
  Vec e_x, e_u;
  Mat e_xx, e_xu, e_uu;
};

// As the model reports them: Gradient(), Hessian() (dense), ControlGradient(),
// MixedHessian(), ControlHessian().
inline ModelDerivatives ReportedDerivatives(const Model& m, const Vec& x, const Vec& u) {
  ModelDerivatives d;
  m.Gradient(x, u, &d.e_x);
  SparseMatrix h = m.HessianPattern();
  m.Hessian(x, u, &h);
  d.e_xx = Mat(h);
  m.ControlGradient(x, u, &d.e_u);
  m.MixedHessian(x, u, &d.e_xu);
  m.ControlHessian(x, u, &d.e_uu);
  return d;
}

// By central differences: E_x and E_u of Energy(), E_xx and E_xu of Gradient(), E_uu of
// ControlGradient().
inline ModelDerivatives CentralDifferences(const Model& m, const Vec& x, const Vec& u, double h) {
  auto energy_x = [&](const Vec& xs) { return m.Energy(xs, u); };
  auto energy_u = [&](const Vec& us) { return m.Energy(x, us); };
  auto gradient_x = [&](const Vec& xs) {
    Vec g;
    m.Gradient(xs, u, &g);
    return g;
  };
  auto gradient_u = [&](const Vec& us) {
    Vec g;
    m.Gradient(x, us, &g);
    return g;
  };
  auto control_gradient_u = [&](const Vec& us) {
    Vec eu;
    m.ControlGradient(x, us, &eu);
    return eu;
  };
  return {.e_x = CentralGradient(energy_x, x, h),
          .e_u = CentralGradient(energy_u, u, h),
          .e_xx = CentralJacobian(gradient_x, x, h),
          .e_xu = CentralJacobian(gradient_u, u, h),
          .e_uu = CentralJacobian(control_gradient_u, u, h)};
}

// The largest entry of |a - b| over the largest of |b| (at least 1): small when a matches
// the reference b entry by entry, whatever b's scale.
inline double MaxRelativeError(const Mat& a, const Mat& b) {
  return (a - b).cwiseAbs().maxCoeff() / std::max(1.0, b.cwiseAbs().maxCoeff());
}

}  // namespace snapthread::test_support
