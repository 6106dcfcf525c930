// The standard cusp (2.9)/(2.16): E = T^4/4 + Y T^2/2 + X T, state T, controls (X, Y).
// Equilibria satisfy (2.13) T^3 + Y T + X = 0; folds lie on 27 X^2 = -4 Y^3.
#include <cmath>

#include "models/one_state_model.h"
#include "models/registry.h"

namespace snapthread {
namespace {

constexpr char kName[] = "cusp";

class CuspModel final : public internal::OneStateModel {
 public:
  std::string_view Name() const override { return kName; }
  int NumControls() const override { return 2; }
  int SpatialDimension() const override { return 2; }

  double Energy(const Vec& x, const Vec& u) const override {
    const double t = x[0];
    return 0.25 * t * t * t * t + 0.5 * u[1] * t * t + u[0] * t;
  }
  void Gradient(const Vec& x, const Vec& u, Vec* g) const override {
    const double t = x[0];
    if (g->size() != 1) g->resize(1);
    (*g)[0] = t * t * t + u[1] * t + u[0];  // (2.13)
  }
  void Hessian(const Vec& x, const Vec& u, SparseMatrix* h) const override {
    ShapeHessian(h);
    h->valuePtr()[0] = 3.0 * x[0] * x[0] + u[1];
  }
  void ControlGradient(const Vec& x, const Vec&, Vec* eu) const override {
    if (eu->size() != 2) eu->resize(2);
    (*eu)[0] = x[0];
    (*eu)[1] = 0.5 * x[0] * x[0];
  }
  void MixedHessian(const Vec& x, const Vec&, Mat* exu) const override {
    if (exu->rows() != 1 || exu->cols() != 2) exu->resize(1, 2);
    (*exu)(0, 0) = 1.0;
    (*exu)(0, 1) = x[0];
  }
  void ControlHessian(const Vec&, const Vec&, Mat* euu) const override {
    if (euu->rows() != 2 || euu->cols() != 2) euu->resize(2, 2);
    euu->setZero();
  }
  Vec InitialState(const Vec& u) const override {
    // The real root of T^3 + Y T + X = 0 of largest |T| on the side opposite to X is
    // a minimum; start from the cubic's dominant balance.
    const double t = -std::cbrt(u[0]);
    return Vec::Constant(1, t);
  }
  void NodePositions(const Vec& x, const Vec&, Eigen::Matrix3Xd* nodes) const override {
    nodes->resize(3, 1);
    nodes->col(0) << x[0], 0.0, 0.0;
  }
  double ForceScale() const override { return 1.0; }
};

}  // namespace

ModelRegistration CuspRegistration() {
  return {.name = kName,
          .doc = "the standard cusp E = T^4/4 + Y T^2/2 + X T (2.9)",
          .factory = [](const ModelParams&) -> std::unique_ptr<Model> { return std::make_unique<CuspModel>(); },
          .capabilities = {.grasp_layout = PlanarGrasp}};
}

}  // namespace snapthread
