// The Zeeman catastrophe machine (2.4): a unit wheel turning about (0, 0), with the
// wheel point P = (-sin θ, -cos θ) tied by two unit-rest-length elastic strings, one to
// the anchor (0, -3), the other to the grasp (X, Y):
//   E = (r1 - 1)^2 + (r2 - 1)^2,  r1 = |P - (0,-3)| = sqrt(sin²θ + (cos θ - 3)²),
//                                 r2 = |(X,Y) - P| = sqrt((X + sin θ)² + (Y + cos θ)²).
// State θ, controls (X, Y). The cusp is at X = 0, Y = (3 + √33)/4 (where E_θθ(θ=0) = 0).
//
// Derivatives: with q = r² each string term is (√q - 1)² = q - 2√q + 1, so for any
// variables α, β:  ∂ = q_α (1 - 1/r),  ∂² = q_αβ (1 - 1/r) + q_α q_β / (2 r³).
#include <algorithm>
#include <cmath>
#include <numbers>

#include "models/one_state_model.h"
#include "models/registry.h"

namespace snapthread {
namespace {

constexpr char kName[] = "zeeman";

struct StringTerms {
  double e = 0.0;     // energy
  double et = 0.0;    // E_θ
  double ett = 0.0;   // E_θθ
  double ex = 0.0, ey = 0.0;             // E_X, E_Y
  double etx = 0.0, ety = 0.0;           // E_θX, E_θY
  double exx = 0.0, eyy = 0.0, exy = 0.0;  // E_XX, E_YY, E_XY
};

// All derivatives at once: the model is one variable, so computing everything costs
// about as much as computing any single entry.
StringTerms Evaluate(double theta, double big_x, double big_y) {
  const double s = std::sin(theta);
  const double c = std::cos(theta);
  StringTerms out;
  // Anchored string: p = r1² = 10 - 6 cos θ, p_θ = 6 sin θ, p_θθ = 6 cos θ.
  const double p = 10.0 - 6.0 * c;
  const double r1 = std::sqrt(p);
  const double p_t = 6.0 * s;
  const double p_tt = 6.0 * c;
  out.e = (r1 - 1.0) * (r1 - 1.0);
  out.et = p_t * (1.0 - 1.0 / r1);
  out.ett = p_tt * (1.0 - 1.0 / r1) + p_t * p_t / (2.0 * p * r1);
  // Grasped string: q = a² + b², a = X + sin θ, b = Y + cos θ.
  const double a = big_x + s;
  const double b = big_y + c;
  const double q = a * a + b * b;
  const double r2 = std::sqrt(q);
  const double k1 = 1.0 - 1.0 / r2;          // multiplies q_α and q_αβ
  const double k2 = 1.0 / (2.0 * q * r2);    // multiplies q_α q_β
  const double q_t = 2.0 * (a * c - b * s);
  const double q_tt = 2.0 * (1.0 - a * s - b * c);
  const double q_x = 2.0 * a;
  const double q_y = 2.0 * b;
  const double q_tx = 2.0 * c;
  const double q_ty = -2.0 * s;
  out.e += (r2 - 1.0) * (r2 - 1.0);
  out.et += q_t * k1;
  out.ett += q_tt * k1 + q_t * q_t * k2;
  out.ex = q_x * k1;
  out.ey = q_y * k1;
  out.etx = q_tx * k1 + q_t * q_x * k2;
  out.ety = q_ty * k1 + q_t * q_y * k2;
  out.exx = 2.0 * k1 + q_x * q_x * k2;
  out.eyy = 2.0 * k1 + q_y * q_y * k2;
  out.exy = q_x * q_y * k2;
  return out;
}

class ZeemanModel final : public internal::OneStateModel {
 public:
  std::string_view Name() const override { return kName; }
  int NumControls() const override { return 2; }
  int SpatialDimension() const override { return 2; }

  double Energy(const Vec& x, const Vec& u) const override {
    const double s = std::sin(x[0]);
    const double c = std::cos(x[0]);
    const double r1 = std::sqrt(s * s + (c - 3.0) * (c - 3.0));
    const double r2 = std::hypot(u[0] + s, u[1] + c);
    return (r1 - 1.0) * (r1 - 1.0) + (r2 - 1.0) * (r2 - 1.0);  // (2.4)
  }
  void Gradient(const Vec& x, const Vec& u, Vec* g) const override {
    if (g->size() != 1) g->resize(1);
    (*g)[0] = Evaluate(x[0], u[0], u[1]).et;
  }
  void Hessian(const Vec& x, const Vec& u, SparseMatrix* h) const override {
    ShapeHessian(h);
    h->valuePtr()[0] = Evaluate(x[0], u[0], u[1]).ett;
  }
  void ControlGradient(const Vec& x, const Vec& u, Vec* eu) const override {
    if (eu->size() != 2) eu->resize(2);
    const StringTerms t = Evaluate(x[0], u[0], u[1]);
    (*eu)[0] = t.ex;
    (*eu)[1] = t.ey;
  }
  void MixedHessian(const Vec& x, const Vec& u, Mat* exu) const override {
    if (exu->rows() != 1 || exu->cols() != 2) exu->resize(1, 2);
    const StringTerms t = Evaluate(x[0], u[0], u[1]);
    (*exu)(0, 0) = t.etx;
    (*exu)(0, 1) = t.ety;
  }
  void ControlHessian(const Vec& x, const Vec& u, Mat* euu) const override {
    if (euu->rows() != 2 || euu->cols() != 2) euu->resize(2, 2);
    const StringTerms t = Evaluate(x[0], u[0], u[1]);
    (*euu)(0, 0) = t.exx;
    (*euu)(0, 1) = t.exy;
    (*euu)(1, 0) = t.exy;
    (*euu)(1, 1) = t.eyy;
  }
  // The global minimum over θ: a grid fine enough that every local minimum of this
  // smooth two-string energy has a grid point in its basin, then Newton polishing.
  // Deterministic (ties resolve to the first grid point, θ from -π upwards).
  Vec InitialState(const Vec& u) const override {
    constexpr int kGrid = 720;
    constexpr int kPolish = 8;
    Vec x(1);
    double best_theta = 0.0;
    double best_e = INFINITY;
    for (int i = 0; i < kGrid; ++i) {
      x[0] = -std::numbers::pi + 2.0 * std::numbers::pi * i / kGrid;
      const double e = Energy(x, u);
      if (e < best_e) {
        best_e = e;
        best_theta = x[0];
      }
    }
    double theta = best_theta;
    for (int it = 0; it < kPolish; ++it) {
      const StringTerms t = Evaluate(theta, u[0], u[1]);
      // Only a convex Newton step moves toward the minimum; a grid point sits within
      // half a cell of it, so the step is also capped to that distance.
      if (!(t.ett > 0.0)) break;
      const double kCell = 2.0 * std::numbers::pi / kGrid;
      const double step = std::clamp(-t.et / t.ett, -kCell, kCell);
      theta += step;
      if (std::abs(step) < 1e-15) break;
    }
    x[0] = theta;
    if (!(Energy(x, u) <= best_e)) x[0] = best_theta;
    return x;
  }
  void NodePositions(const Vec& x, const Vec& u, Eigen::Matrix3Xd* nodes) const override {
    if (nodes->cols() != 4) nodes->resize(3, 4);
    nodes->col(0) << 0.0, 0.0, 0.0;                                 // wheel centre
    nodes->col(1) << -std::sin(x[0]), -std::cos(x[0]), 0.0;         // wheel point P
    nodes->col(2) << 0.0, -3.0, 0.0;                                // fixed anchor
    nodes->col(3) << u[0], u[1], 0.0;                               // grasp (X, Y)
  }
  double ForceScale() const override { return 1.0; }
};

}  // namespace

ModelRegistration ZeemanRegistration() {
  return {.name = kName,
          .doc = "the Zeeman catastrophe machine: a wheel held by two elastic strings (2.4)",
          .factory = [](const ModelParams&) -> std::unique_ptr<Model> { return std::make_unique<ZeemanModel>(); },
          .capabilities = {.grasp_layout = PlanarGrasp}};
}

}  // namespace snapthread
