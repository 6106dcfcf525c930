#include "solvers/symmetry_orbits.h"

#include <cmath>
#include <numbers>

namespace snapthread {
namespace {

// Steps of 1/16 turn find the bottom of a near-symmetric orbit (E ~ a + b cos t) with
// room for higher harmonics; golden section refines it to ~1e-5 rad, so the Newton
// steps that follow start within their quadratic region.
constexpr int kSamples = 16;
constexpr int kGoldenSteps = 30;

}  // namespace

SymmetryOrbits::SymmetryOrbits(const Model& model)
    : model_(model), symmetry_(model.symmetry()), contact_(model.contact()) {
  const int n = model.NumStates();
  trial_.resize(n);
  best_.resize(n);
}

bool SymmetryOrbits::MoveDownhill(const Vec& u, Vec* x) {
  bool moved = false;
  if (symmetry_ == nullptr) return moved;
  for (int k = 0; k < symmetry_->NumSymmetries(); ++k) {
    auto energy_at = [&](double t) {
      symmetry_->ApplySymmetry(k, t, *x, u, &trial_);
      return model_.Energy(trial_, u);
    };
    const double e0 = model_.Energy(*x, u);
    if (!std::isfinite(e0)) return moved;
    // Downhill along the orbit only, as far as E keeps falling: a curved line search
    // that never crosses a barrier (a jump to a far side of the orbit that is lower but
    // walled off would be no quasi-static motion).
    const double step = 2.0 * std::numbers::pi / kSamples;
    const double noise = 1e-12 * (1.0 + std::abs(e0));
    const double e_plus = energy_at(step), e_minus = energy_at(-step);
    const double dir = e_plus <= e_minus ? 1.0 : -1.0;
    double best_e = std::min(e_plus, e_minus);
    if (!(best_e < e0 - noise)) continue;  // a minimum along the orbit is within a step
    double best_t = dir * step;
    for (int j = 2; j < kSamples; ++j) {
      const double e = energy_at(dir * j * step);
      if (!(std::isfinite(e) && e < best_e)) break;
      best_e = e;
      best_t = dir * j * step;
    }
    // Golden section on [best_t - step, best_t + step] (the sampled minimum's bracket).
    const double ratio = 0.5 * (std::sqrt(5.0) - 1.0);
    double a = best_t - step, b = best_t + step;
    double c = b - ratio * (b - a), d = a + ratio * (b - a);
    double ec = energy_at(c), ed = energy_at(d);
    for (int it = 0; it < kGoldenSteps; ++it) {
      if (ec < ed) {
        b = d;
        d = c;
        ed = ec;
        c = b - ratio * (b - a);
        ec = energy_at(c);
      } else {
        a = c;
        c = d;
        ec = ed;
        d = a + ratio * (b - a);
        ed = energy_at(d);
      }
    }
    const double t = ec < ed ? c : d;
    if (std::min(ec, ed) < best_e) best_t = t;
    symmetry_->ApplySymmetry(k, best_t, *x, u, &best_);
    // Self-contact: the move is a jump to the orbit's point; it must not carry a segment
    // through another on the way (CCD on the chord), else the orbit is left alone.
    trial_ = best_ - *x;
    if (contact_ != nullptr && contact_->MaxStepFraction(*x, trial_, u) < 1.0) continue;
    x->swap(best_);
    moved = true;
  }
  return moved;
}

}  // namespace snapthread
