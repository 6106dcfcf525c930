// What the two chains (curve2d, thread3d) share: the derivatives E_x, E_xx, E_u, E_xu,
// E_uu assembled from per-term local derivatives (hessian_assembly.h), and the
// parameter schema of a chain of n segments (n, segment length, β, γ).
//
// A chain derives from ChainModel<Derived> (CRTP, so the per-term callback is inlined
// and nothing allocates) and provides
//   template <class F> void Local(int t, const Vec& x, const Vec& u, bool want_h, F&& f) const
// calling f(local gradient, local Hessian (valid if want_h), leading dimension) for term t
// in the term's assembly variables. Its constructor registers the terms with
// assembly_.AddTerm and then calls FinishTerms().
#pragma once

#include <algorithm>
#include <string>
#include <vector>

#include "models/hessian_assembly.h"
#include "models/model.h"
#include "models/params.h"

namespace snapthread::internal {

template <class Derived>
class ChainModel : public Model {
 public:
  int NumStates() const override { return assembly_.NumStates(); }
  int NumControls() const override { return assembly_.NumControls(); }

  void Gradient(const Vec& x, const Vec& u, Vec* g) const override {
    if (g->size() != NumStates()) g->resize(NumStates());
    g->setZero();
    for (int t = 0; t < assembly_.NumTerms(); ++t) {
      Self().Local(t, x, u, /*want_h=*/false,
                   [&](const double* lg, const double*, int) { assembly_.AddGradient(t, lg, g->data()); });
    }
  }

  const SparseMatrix& HessianPattern() const override { return assembly_.Pattern(); }

  void Hessian(const Vec& x, const Vec& u, SparseMatrix* h) const override {
    const SparseMatrix& pattern = assembly_.Pattern();
    const int nx = NumStates();
    if (h->rows() != nx || h->cols() != nx || h->nonZeros() != pattern.nonZeros() || !h->isCompressed()) {
      *h = pattern;
    }
    double* values = h->valuePtr();
    std::fill(values, values + pattern.nonZeros(), 0.0);
    for (int t = 0; t < assembly_.NumTerms(); ++t) {
      Self().Local(t, x, u, /*want_h=*/true, [&](const double*, const double* lh, int ld) {
        assembly_.AddHessian(t, lh, ld, values);
      });
    }
  }

  void ControlGradient(const Vec& x, const Vec& u, Vec* eu) const override {
    const int nu = NumControls();
    if (eu->size() != nu) eu->resize(nu);
    eu->setZero();
    for (int t : control_terms_) {
      Self().Local(t, x, u, false, [&](const double* lg, const double*, int) {
        assembly_.AddControlGradient(t, lg, eu->data());
      });
    }
  }

  void MixedHessian(const Vec& x, const Vec& u, Mat* exu) const override {
    const int nx = NumStates(), nu = NumControls();
    if (exu->rows() != nx || exu->cols() != nu) exu->resize(nx, nu);
    exu->setZero();
    for (int t : control_terms_) {
      Self().Local(t, x, u, true, [&](const double*, const double* lh, int ld) {
        assembly_.AddMixedHessian(t, lh, ld, exu);
      });
    }
  }

  void ControlHessian(const Vec& x, const Vec& u, Mat* euu) const override {
    const int nu = NumControls();
    if (euu->rows() != nu || euu->cols() != nu) euu->resize(nu, nu);
    euu->setZero();
    for (int t : control_terms_) {
      Self().Local(t, x, u, true, [&](const double*, const double* lh, int ld) {
        assembly_.AddControlHessian(t, lh, ld, euu);
      });
    }
  }

  int HessianBandwidth() const override { return assembly_.Bandwidth(); }

 protected:
  ChainModel(int num_states, int num_controls) : assembly_(num_states, num_controls) {}

  // Builds the pattern once every term is registered, and notes the terms that touch u.
  void FinishTerms() {
    assembly_.Finalize();
    for (int t = 0; t < assembly_.NumTerms(); ++t) {
      if (assembly_.TouchesControls(t)) control_terms_.push_back(t);
    }
  }

  // Clamped–pinned Euler buckling load 20.19 EI / L² of a chain of n segments of length
  // l, with EI = c l for a bending term c (1 - t_i·t_{i+1}) (c (1 - cos φ) ≈ c φ²/2 =
  // (c l) κ² l / 2 per joint) and L = n l.
  static double EulerLoad(int n, double l, double c) {
    const double total = n * l;
    return 20.19 * c * l / (total * total);
  }

  HessianAssembly assembly_;

 private:
  const Derived& Self() const { return static_cast<const Derived&>(*this); }

  std::vector<int> control_terms_;
};

// The schema every chain starts from: n >= 2, segment_length, bending and stretching
// (the docs say where the chain uses β and γ), all > 0.
std::vector<ParamSpec> ChainParamSpecs(const std::string& bending_doc, const std::string& stretching_doc);

}  // namespace snapthread::internal
