// The planar elastic strip of the seed (2.1–2.2): n segments, nodes p_0 .. p_n,
//   E = Σ_{i=1..n} γ (|v_i| - l)²  +  Σ_{i=1..n-1} β (1 - t_i · t_{i+1}),
// v_i = p_i - p_{i-1}, t_i = v_i / |v_i|. The seed writes the bending sum as Σ b_i with
// b_i = 1 - t_{i-1}·t_i: bending lives only at the interior nodes 1..n-1 that join two
// segments. p_0 = (0, 0) and y_1 = 0 clamp the first segment to the x-axis (2.1); the
// grasp holds p_n = (X, Y) = u. State x = [x_1, x_2, y_2, ..., x_{n-1}, y_{n-1}] (2n - 3).
#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include "models/chain_model.h"
#include "models/chain_terms.h"
#include "models/registry.h"

namespace snapthread {
namespace {

using internal::BendTerm;
using internal::ChainModel;
using internal::StretchTerm;
using V2 = Eigen::Vector2d;

constexpr char kName[] = "curve2d";

class Curve2dModel final : public ChainModel<Curve2dModel> {
 public:
  explicit Curve2dModel(const ModelParams& params)
      : ChainModel(params, 2 * params.Integer("n") - 3, 2),
        l_(params.Number("segment_length")),
        beta_(params.Number("bending")),
        gamma_(params.Number("stretching")) {
    AddChainTerms();
  }

  std::string_view Name() const override { return kName; }
  int SpatialDimension() const override { return 2; }

  // (2.1): Σ γ (|v_i| - l)² + Σ β (1 - t_i · t_{i+1}).
  double Energy(const Vec& x, const Vec& u) const override {
    return ChainEnergy<2>(x, u, 0.0, beta_, gamma_, l_);
  }

  // Nodes evenly spaced on the chord from (0, 0) to u, plus a bump 1e-3 l sin(π i / n)
  // along the chord's normal. Why the bump: the perfectly straight compressed strip is an
  // equilibrium by symmetry (every bending gradient vanishes), unstable past buckling,
  // and Newton started exactly on it stays there for ever; the tiny deterministic bump
  // picks one buckling side. y_1 = 0 is then re-imposed (the clamp).
  Vec InitialState(const Vec& u) const override {
    const V2 chord(u[0], u[1]);
    const double length = chord.norm();
    const V2 along = length > 1e-12 * l_ ? V2(chord / length) : V2(1.0, 0.0);
    const V2 normal(-along.y(), along.x());
    Vec x(nx_);
    for (int i = 1; i <= n_ - 1; ++i) {
      const V2 p = (static_cast<double>(i) / n_) * chord +
                   (1e-3 * l_ * std::sin(std::numbers::pi * i / n_)) * normal;
      if (i == 1) {
        x[0] = p.x();
      } else {
        x[1 + 2 * (i - 2)] = p.x();
        x[2 + 2 * (i - 2)] = p.y();
      }
    }
    return x;
  }

  void NodePositions(const Vec& x, const Vec& u, Eigen::Matrix3Xd* nodes) const override {
    if (nodes->cols() != n_ + 1) nodes->resize(3, n_ + 1);
    for (int i = 0; i <= n_; ++i) {
      const V2 p = Node(i, x, u);
      nodes->col(i) << p.x(), p.y(), 0.0;
    }
  }
  double Probe(const Vec& x, const Vec& u) const override { return Node(n_ / 2, x, u).y(); }
  // Clamped–pinned Euler buckling load with EI = β l (see chain_model.h).
  double ForceScale() const override { return EulerLoad(n_, l_, beta_); }

 private:
  friend class ChainModel<Curve2dModel>;
  struct Term {
    bool bend;
    int first_node;
  };

  // Generalised index of coordinate k of node i (see hessian_assembly.h): -1 if fixed.
  int NodeVar(int i, int k) const {
    if (i == 0) return -1;
    if (i == 1) return k == 0 ? 0 : -1;
    if (i == n_) return nx_ + k;
    return 1 + 2 * (i - 2) + k;
  }
  V2 Node(int i, const Vec& x, const Vec& u) const {
    if (i == 0) return V2::Zero();
    if (i == 1) return V2(x[0], 0.0);
    if (i == n_) return V2(u[0], u[1]);
    return V2(x[1 + 2 * (i - 2)], x[2 + 2 * (i - 2)]);
  }
  void AddTerm(bool bend, int first_node) {
    int vars[6];
    const int nodes = bend ? 3 : 2;
    for (int a = 0; a < nodes; ++a) {
      for (int k = 0; k < 2; ++k) vars[2 * a + k] = NodeVar(first_node + a, k);
    }
    assembly_.AddTerm(vars, 2 * nodes);
    terms_.push_back({bend, first_node});
  }
  // Calls f(local gradient, local Hessian or null, leading dimension) for term t;
  // returns the term's energy (the value ChainEnergy adds for it).
  template <class F>
  double Local(int t, const Vec& x, const Vec& u, bool want_h, F&& f) const {
    const int a = terms_[t].first_node;
    if (terms_[t].bend) {
      Eigen::Matrix<double, 6, 1> lg;
      Eigen::Matrix<double, 6, 6> lh;
      const double e = BendTerm<2>(Node(a, x, u), Node(a + 1, x, u), Node(a + 2, x, u), beta_, &lg,
                                   want_h ? &lh : nullptr);
      f(lg.data(), lh.data(), 6);
      return e;
    }
    Eigen::Matrix<double, 4, 1> lg;
    Eigen::Matrix<double, 4, 4> lh;
    const double e = StretchTerm<2>(Node(a, x, u), Node(a + 1, x, u), gamma_, l_, &lg, want_h ? &lh : nullptr);
    f(lg.data(), lh.data(), 4);
    return e;
  }
  // The energy of a chain without self-contact is its terms' (ChainModel's hook).
  double ContactEnergy(const Vec&, const Vec&) const { return 0.0; }
  double EnergyShift() const { return 0.0; }

  const double l_;
  const double beta_;
  const double gamma_;
  std::vector<Term> terms_;
};

}  // namespace

ModelRegistration Curve2dRegistration() {
  return {.name = kName,
          .doc = "planar elastic strip of n segments, clamped at the origin, held at its end (2.1-2.2)",
          .params = internal::ChainParamSpecs("beta in beta (1 - t_i . t_{i+1}) (2.1)", "gamma in gamma (|v_i| - l)^2 (2.1)"),
          .factory = [](const ModelParams& p) -> std::unique_ptr<Model> { return std::make_unique<Curve2dModel>(p); },
          .capabilities = {.grasp_layout = PlanarGrasp, .chain = ChainSpec{.per_length = {"bending", "stretching"}}}};
}

}  // namespace snapthread
