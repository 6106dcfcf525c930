// What the two chains (curve2d, thread3d) share: the derivatives E_x, E_xx, E_u, E_xu,
// E_uu assembled from per-term local derivatives (hessian_assembly.h), and the
// parameter schema of a chain of n segments (n, segment length, β, γ).
//
// A chain derives from ChainModel<Derived> (CRTP, so the per-term callback is inlined
// and nothing allocates) and provides
//   template <class F> void Local(int t, const Vec& x, const Vec& u, bool want_h, F&& f) const
// calling f(local gradient, local Hessian (valid if want_h), leading dimension) for term t
// in the term's assembly variables, and
//   void AddTerm(bool bend, int first_node)
// registering one term with assembly_.AddTerm and in terms_ (elements with `bend` and
// `first_node`). Its constructor calls AddChainTerms(); its Energy can be ChainEnergy.
#pragma once

#include <algorithm>
#include <string>
#include <vector>

#include "models/band_assembly_capability.h"
#include "models/chain_terms.h"
#include "models/hessian_assembly.h"
#include "models/model.h"
#include "models/params.h"

namespace snapthread::internal {

template <class Derived>
class ChainModel : public Model, public BandAssemblyCapability {
 public:
  int NumStates() const override { return assembly_.NumStates(); }
  int NumControls() const override { return assembly_.NumControls(); }

  void Gradient(const Vec& x, const Vec& u, Vec* g) const override {
    if (g->size() != NumStates()) g->resize(NumStates());
    g->setZero();
    for (int t = 0; t < chain_terms_; ++t) {
      Self().Local(t, x, u, /*want_h=*/false,
                   [&](const double* lg, const double*, int) { assembly_.AddGradient(t, lg, g->data()); });
    }
    Self().AddContactGradient(x, u, g);
  }

  const SparseMatrix& HessianPattern() const override { return assembly_.Pattern(); }
  int HessianPatternVersion() const override { return assembly_.PatternVersion(); }

  void Hessian(const Vec& x, const Vec& u, SparseMatrix* h) const override {
    // StoreHessian: every chain slot is reached by a chain term first, so no clearing pass;
    // slots only a contact pair reaches are cleared when the model has contact.
    Self().CoverContacts(x, u);
    double* values = assembly_.Values(h, assembly_.DynamicTerms());
    for (int t = 0; t < chain_terms_; ++t) {
      Self().Local(t, x, u, /*want_h=*/true, [&](const double*, const double* lh, int ld) {
        assembly_.StoreHessian(t, lh, ld, values);
      });
    }
    Self().AddContactHessian(x, u, values);
  }

  // One pass over the terms for both: each term's local derivatives are computed once
  // (Gradient() alone costs a third of Hessian()). The same operations as the two
  // separate passes, so the same bits.
  void GradientAndHessian(const Vec& x, const Vec& u, Vec* g, SparseMatrix* h) const override {
    if (g->size() != NumStates()) g->resize(NumStates());
    g->setZero();
    Self().CoverContacts(x, u);
    double* values = assembly_.Values(h, assembly_.DynamicTerms());
    for (int t = 0; t < chain_terms_; ++t) {
      Self().Local(t, x, u, /*want_h=*/true, [&](const double* lg, const double* lh, int ld) {
        assembly_.AddGradient(t, lg, g->data());
        assembly_.StoreHessian(t, lh, ld, values);
      });
    }
    Self().AddContactGradient(x, u, g);
    Self().AddContactHessian(x, u, values);
  }

  // The same pass adding up the terms' energies in ChainEnergy's order (the energy
  // shift first, then term by term, then self-contact), so E has Energy()'s bits.
  double EnergyGradientAndHessian(const Vec& x, const Vec& u, Vec* g, SparseMatrix* h) const override {
    if (g->size() != NumStates()) g->resize(NumStates());
    g->setZero();
    Self().CoverContacts(x, u);
    double* values = assembly_.Values(h, assembly_.DynamicTerms());
    double e = Self().EnergyShift();
    for (int t = 0; t < chain_terms_; ++t) {
      e += Self().Local(t, x, u, /*want_h=*/true, [&](const double* lg, const double* lh, int ld) {
        assembly_.AddGradient(t, lg, g->data());
        assembly_.StoreHessian(t, lh, ld, values);
      });
    }
    Self().AddContactGradient(x, u, g);
    Self().AddContactHessian(x, u, values);
    return e + Self().ContactEnergy(x, u);
  }

  const BandAssemblyCapability* band_assembly() const override { return this; }
  bool EnergyGradientAndBandHessian(const Vec& x, const Vec& u, Vec* g, double* band, int bandwidth,
                                    double* energy) const override {
    // Self-contact adds its pairs through the compressed matrix only.
    if (assembly_.DynamicTerms() || bandwidth != assembly_.Bandwidth()) return false;
    if (g->size() != NumStates()) g->resize(NumStates());
    g->setZero();
    std::fill(band, band + static_cast<std::ptrdiff_t>(NumStates()) * (bandwidth + 1), 0.0);
    double e = Self().EnergyShift();
    for (int t = 0; t < chain_terms_; ++t) {
      e += Self().Local(t, x, u, /*want_h=*/true, [&](const double* lg, const double* lh, int ld) {
        assembly_.AddGradient(t, lg, g->data());
        assembly_.AddBandHessian(t, lh, ld, band);
      });
    }
    Self().AddContactGradient(x, u, g);
    *energy = e + Self().ContactEnergy(x, u);
    return true;
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
    Self().AddContactControlGradient(x, u, eu);
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
    Self().AddContactMixedHessian(x, u, exu);
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
    Self().AddContactControlHessian(x, u, euu);
  }

  // One pass over the control terms for all three (the same operations, the same bits).
  void ControlDerivatives(const Vec& x, const Vec& u, Vec* eu, Mat* exu, Mat* euu) const override {
    const int nx = NumStates(), nu = NumControls();
    if (eu->size() != nu) eu->resize(nu);
    if (exu->rows() != nx || exu->cols() != nu) exu->resize(nx, nu);
    if (euu->rows() != nu || euu->cols() != nu) euu->resize(nu, nu);
    eu->setZero();
    exu->setZero();
    euu->setZero();
    for (int t : control_terms_) {
      Self().Local(t, x, u, true, [&](const double* lg, const double* lh, int ld) {
        assembly_.AddControlGradient(t, lg, eu->data());
        assembly_.AddMixedHessian(t, lh, ld, exu);
        assembly_.AddControlHessian(t, lh, ld, euu);
      });
    }
    Self().AddContactControlGradient(x, u, eu);
    Self().AddContactMixedHessian(x, u, exu);
    Self().AddContactControlHessian(x, u, euu);
  }

  int HessianBandwidth() const override { return assembly_.Bandwidth(); }

 protected:
  // params.n is the number of segments (ChainParamSpecs).
  ChainModel(const ModelParams& params, int num_states, int num_controls)
      : n_(params.Integer("n")), nx_(num_states), assembly_(num_states, num_controls) {}

  // Registers the terms in the chains' order (stretching of segments 1..n, then bending
  // at joints 1..n-1) and a model's self-contact pairs after them (RegisterContact), then
  // builds the pattern once and notes the chain terms that touch u.
  void AddChainTerms() {
    Derived& self = static_cast<Derived&>(*this);
    for (int i = 1; i <= n_; ++i) self.AddTerm(false, i - 1);
    for (int j = 1; j <= n_ - 1; ++j) self.AddTerm(true, j - 1);
    chain_terms_ = assembly_.NumTerms();
    self.RegisterContact();
    assembly_.Finalize();
    for (int t = 0; t < chain_terms_; ++t) {
      if (assembly_.TouchesControls(t)) control_terms_.push_back(t);
    }
  }

  // shift + the sum, in term order, of the stretching terms stretch (|v| - rest)² and
  // the bending terms bend (1 - w·w') (chain_terms.h), nodes from Derived::Node.
  template <int D>
  double ChainEnergy(const Vec& x, const Vec& u, double shift, double bend, double stretch,
                     double rest) const {
    const Derived& self = Self();
    double e = shift;
    for (const auto& term : self.terms_) {
      const int a = term.first_node;
      e += term.bend ? BendTerm<D>(self.Node(a, x, u), self.Node(a + 1, x, u),
                                   self.Node(a + 2, x, u), bend, nullptr, nullptr)
                     : StretchTerm<D>(self.Node(a, x, u), self.Node(a + 1, x, u), stretch, rest,
                                      nullptr, nullptr);
    }
    return e;
  }

  // Clamped–pinned Euler buckling load 20.19 EI / L² of a chain of n segments of length
  // l, with EI = c l for a bending term c (1 - t_i·t_{i+1}) (c (1 - cos φ) ≈ c φ²/2 =
  // (c l) κ² l / 2 per joint) and L = n l.
  static double EulerLoad(int n, double l, double c) {
    const double total = n * l;
    return 20.19 * c * l / (total * total);
  }

  // Self-contact hooks (thread3d defines them; a chain without contact has none).
  void RegisterContact() {}
  void CoverContacts(const Vec&, const Vec&) const {}  // before E_xx is written (contact_terms.h)
  void AddContactGradient(const Vec&, const Vec&, Vec*) const {}
  void AddContactHessian(const Vec&, const Vec&, double*) const {}
  void AddContactControlGradient(const Vec&, const Vec&, Vec*) const {}
  void AddContactMixedHessian(const Vec&, const Vec&, Mat*) const {}
  void AddContactControlHessian(const Vec&, const Vec&, Mat*) const {}

  const int n_;   // segments; nodes p_0 .. p_n
  const int nx_;  // states
  HessianAssembly assembly_;
  int chain_terms_ = 0;  // assembly terms 0 .. chain_terms_-1 are the chain's own

 private:
  const Derived& Self() const { return static_cast<const Derived&>(*this); }

  std::vector<int> control_terms_;
};

// The schema every chain starts from: n >= 2, segment_length, bending and stretching
// (the docs say where the chain uses β and γ), all > 0.
std::vector<ParamSpec> ChainParamSpecs(const std::string& bending_doc, const std::string& stretching_doc);

}  // namespace snapthread::internal
