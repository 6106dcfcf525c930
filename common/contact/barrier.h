// IPC's log barrier (Li et al. 2020, "Incremental Potential Contact", eq. (5)),
//   b(d, d̂) = -(d - d̂)² log(d / d̂)  for 0 < d < d̂,  0 for d ≥ d̂,
// C² at d̂ (b, b' and b'' all vanish there) and +∞ as d → 0. As IPC does, it acts on
// squared distances, here of capsules: the argument is the squared centreline distance
// D less the squared contact distance (2r)², so the barrier blows up where the two
// surfaces of radius r touch, and the activation distance d̂ is a gap between surfaces:
//   G = D - (2r)²,  Ĝ = (2r + d̂)² - (2r)²,  E = κ b̃(G / Ĝ),  b̃(x) = -(x - 1)² log x.
// Normalised by Ĝ, b̃ is a pure number and κ is an energy (model energy units).
#pragma once

#include <cmath>
#include <limits>

namespace snapthread::contact {

struct ContactParams {
  bool enabled = false;
  double radius = 0.0;     // capsule radius r: centrelines touch at 2r
  double dhat = 0.0;       // activation gap d̂ between the surfaces (> 0)
  double stiffness = 0.0;  // κ (> 0)

  double ContactDistance() const { return 2.0 * radius; }
  // Centreline distance below which a pair is active: 2r + d̂.
  double ActivationDistance() const { return 2.0 * radius + dhat; }
};

class Barrier {
 public:
  explicit Barrier(const ContactParams& p)
      : kappa_(p.stiffness),
        contact_sq_(4.0 * p.radius * p.radius),
        scale_(p.ActivationDistance() * p.ActivationDistance() - 4.0 * p.radius * p.radius) {}

  // Active (non-zero) for a squared centreline distance below this.
  double ActivationSq() const { return contact_sq_ + scale_; }
  double ContactSq() const { return contact_sq_; }

  // E(D) = κ b̃((D - (2r)²) / Ĝ); d1 = dE/dD, d2 = d²E/dD² (may be null). +∞ (and
  // derivatives +∞/-∞) at or inside contact, where a state is infeasible.
  double Value(double d_sq, double* d1, double* d2) const {
    const double x = (d_sq - contact_sq_) / scale_;
    if (x >= 1.0) {
      if (d1 != nullptr) *d1 = 0.0;
      if (d2 != nullptr) *d2 = 0.0;
      return 0.0;
    }
    if (!(x > 0.0)) {
      constexpr double kInf = std::numeric_limits<double>::infinity();
      if (d1 != nullptr) *d1 = -kInf;
      if (d2 != nullptr) *d2 = kInf;
      return kInf;
    }
    const double lx = std::log(x), xm = x - 1.0;
    // b̃' = -2 (x-1) log x - (x-1)²/x,  b̃'' = -2 log x - 2 (x-1)/x - (x² - 1)/x².
    if (d1 != nullptr) *d1 = kappa_ * (-2.0 * xm * lx - xm * xm / x) / scale_;
    if (d2 != nullptr) *d2 = kappa_ * (-2.0 * lx - 2.0 * xm / x - (x * x - 1.0) / (x * x)) / (scale_ * scale_);
    return -kappa_ * xm * xm * lx;
  }

 private:
  double kappa_;
  double contact_sq_;  // (2r)²
  double scale_;       // Ĝ
};

}  // namespace snapthread::contact
