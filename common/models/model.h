// The energy model interface: every system of the seed (zeeman, cusp, curve2d,
// thread3d) is a smooth energy E(x, u) of internal state x and controls u (the grasp).
//
// Conventions
//  * x has NumStates() entries, u has NumControls() entries.
//  * All derivatives are analytic and are checked against finite differences in
//    tests/model_derivative_test.cc.
//  * The Hessian E_xx is stored as a full symmetric sparse matrix (both triangles)
//    with a pattern fixed at construction (HessianPattern()), but for self-contact's
//    pair blocks (HessianPatternVersion()). Hessian() overwrites the values of a matrix
//    that already has that pattern and must not allocate then: the solvers reuse one
//    matrix and one symbolic factorisation for every step while the pattern holds.
//  * Output vectors/matrices passed by pointer are resized by the callee only when
//    their size is wrong (so a caller that keeps them allocated pays nothing).
#pragma once

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "contact/self_contact.h"
#include "numeric/types.h"

namespace snapthread {

// What a grasp is, as a device sees it: a position with `spatial_dimension` coordinates
// (2 for planar models, 3 in space), followed by a unit grip direction (3 numbers) when
// the model constrains the direction of the held end, or by a rotation vector φ (3
// numbers, rad: the grasp's orientation is exp([φ]×) times its start orientation) when
// the model holds the full pose of the held end (the rod). The scene carries it so the
// device client and the viewers can map poses without building a model.
struct GraspLayout {
  int spatial_dimension = 2;
  bool grip_direction = false;
  bool grip_rotation = false;
  int NumControls() const { return spatial_dimension + (grip_direction || grip_rotation ? 3 : 0); }
};

class Model {
 public:
  virtual ~Model() = default;

  // The name the model is registered under (models/registry.h).
  virtual std::string_view Name() const = 0;
  virtual int NumStates() const = 0;
  virtual int NumControls() const = 0;
  // 2 for planar models (u = (X, Y)), 3 for thread3d.
  virtual int SpatialDimension() const = 0;

  virtual double Energy(const Vec& x, const Vec& u) const = 0;
  // E_x, size NumStates().
  virtual void Gradient(const Vec& x, const Vec& u, Vec* g) const = 0;
  // E_xx with the pattern of HessianPattern(). A model with self-contact changes that
  // pattern (the blocks of the segment pairs near contact, models/contact_terms.h) inside
  // a Hessian evaluation, rarely; HessianPatternVersion() then moves, Hessian() gives
  // *h the new structure, and a solver analyses its factorisation again. 0 for the rest.
  virtual const SparseMatrix& HessianPattern() const = 0;
  virtual int HessianPatternVersion() const { return 0; }
  virtual void Hessian(const Vec& x, const Vec& u, SparseMatrix* h) const = 0;
  // E_x and E_xx at one state, the same values as Gradient() and Hessian(); a model may
  // fuse the two passes over its terms (the solvers call this where both are needed).
  virtual void GradientAndHessian(const Vec& x, const Vec& u, Vec* g, SparseMatrix* h) const {
    Gradient(x, u, g);
    Hessian(x, u, h);
  }
  // E(x, u), E_x and E_xx at one state, the same values as Energy(), Gradient() and
  // Hessian() (to the last bit); returns E. A model may fuse the three passes over its
  // terms (a converged solve needs all three at its warm start).
  virtual double EnergyGradientAndHessian(const Vec& x, const Vec& u, Vec* g, SparseMatrix* h) const {
    GradientAndHessian(x, u, g, h);
    return Energy(x, u);
  }
  // The same with E_xx written straight into band storage instead of a compressed
  // matrix: the lower band of half-bandwidth `bandwidth` (linalg/banded_ldlt.h's layout,
  // A(i, j), i >= j, at band[i (bandwidth + 1) + j - i + bandwidth]; every other slot of
  // the NumStates() (bandwidth + 1) array is set to 0), the values Hessian() gives (to
  // the last bit, but for the sign of a zero). Returns
  // false, writing nothing, where the model cannot (the default; a chain with
  // self-contact; another bandwidth than HessianBandwidth()). The solvers' banded
  // factorisation then skips the copy from a compressed matrix.
  virtual bool EnergyGradientAndBandHessian(const Vec& /*x*/, const Vec& /*u*/, Vec* /*g*/, double* /*band*/,
                                            int /*bandwidth*/, double* /*energy*/) const {
    return false;
  }
  // E_u, size NumControls(). The force on the grasp is F = -E_u (envelope theorem, §2.3.4).
  virtual void ControlGradient(const Vec& x, const Vec& u, Vec* eu) const = 0;
  // E_xu, NumStates() x NumControls() (dense: only a few rows are non-zero).
  virtual void MixedHessian(const Vec& x, const Vec& u, Mat* exu) const = 0;
  // E_uu, NumControls() x NumControls().
  virtual void ControlHessian(const Vec& x, const Vec& u, Mat* euu) const = 0;
  // E_u, E_xu and E_uu at one state, the same values as the three above; a model may
  // fuse their passes over the terms that touch the controls (the tracker's force and K).
  virtual void ControlDerivatives(const Vec& x, const Vec& u, Vec* eu, Mat* exu, Mat* euu) const {
    ControlGradient(x, u, eu);
    MixedHessian(x, u, exu);
    ControlHessian(x, u, euu);
  }
  // A grasp that holds its orientation (GraspLayout::grip_rotation): the torque of the
  // model on the hand about the grasp point, world frame, -dE/dδ for a small world
  // rotation exp([δ]×) of the grasp (the rotation part of -E_u is that torque only while
  // the rotation vector stays on one axis, and loses it at whole turns). false: none.
  virtual bool GraspTorque(const Vec& /*x*/, const Vec& /*u*/, Eigen::Vector3d* /*torque*/) const {
    return false;
  }

  // A natural starting state for controls u (straight thread, wheel at theta = 0, ...).
  virtual Vec InitialState(const Vec& u) const = 0;
  // Node positions for drawing (3 x k, z = 0 for planar models). For zeeman: the
  // wheel centre, the wheel point and both string anchors; for cusp: (T, 0, 0).
  virtual void NodePositions(const Vec& x, const Vec& u, Eigen::Matrix3Xd* nodes) const = 0;
  // One scalar summary of the state for sweeps: theta (zeeman), T (cusp), y of node
  // floor(n/2) (curve2d, thread3d).
  virtual double Probe(const Vec& x, const Vec& u) const = 0;
  // A characteristic magnitude of grasp forces in model units, for relative tolerances.
  virtual double ForceScale() const = 0;
  // Half-bandwidth of E_xx in the variable ordering (for banded factorisations); -1 when
  // not known (a pattern that changes: self-contact).
  virtual int HessianBandwidth() const = 0;

  // Called by the tracker after it accepted the equilibrium x at controls u (after the
  // force and stiffness of that update were computed). A model whose energy is written
  // against lagged data (the rod's time-parallel reference frames, docs/models-rod.md)
  // moves that data to the accepted state here; at x itself E and the equilibrium do not
  // change. Models without history (zeeman, cusp, curve2d, thread3d) have nothing to do.
  virtual void AcceptState(const Vec& /*x*/, const Vec& /*u*/) {}
  // Called by the tracker's Reset before InitialState: forget the lagged data, so a
  // reset starts from the same model a fresh one would be (the rod untwists: its grasp
  // turn count goes back to the rest frames').
  virtual void ResetHistory() {}

  // Self-contact (issue 15; models/contact_terms.h), for models whose segments are
  // capsules that must not pass through each other. Continuous collision detection: the
  // largest alpha in (0, 1] such that the straight step from x to x + alpha dx at
  // controls u moves no segment through another and keeps every pair's gap above a
  // tenth of its value at x (0 if two segments already touch). Every solver step is
  // scaled by it. Models without contact: 1.
  virtual double MaxStepFraction(const Vec& /*x*/, const Vec& /*dx*/, const Vec& /*u*/) const { return 1.0; }
  // The same for a motion that also moves the controls (the tracker's predictor): the
  // node positions go on a straight line from those of (x0, u0) to those of (x1, u1).
  virtual double MaxMotionFraction(const Vec& /*x0*/, const Vec& /*u0*/, const Vec& /*x1*/,
                                   const Vec& /*u1*/) const {
    return 1.0;
  }
  // The active contact pairs with their closest points (status and drawing; allocates).
  virtual std::vector<contact::ContactPoint> ActiveContacts(const Vec& /*x*/, const Vec& /*u*/) const {
    return {};
  }

  // Continuous symmetries: one-parameter groups of rotations x -> S_k(t) x (period 2 pi)
  // that leave E(., u) unchanged for controls on the rotation's axis and nearly so near
  // it (a thread3d grasp on the clamp axis lets the thread roll about it at no cost).
  // Their generators span null directions of E_xx there, along which Newton steps are
  // singular and straight steps crawl round the circle; the solvers step in the
  // complement and move along the orbit itself (solvers/symmetry_orbits.h). The
  // default is none: a model without such a symmetry has nothing to declare.
  virtual int NumSymmetries() const { return 0; }
  // The generator d/dt S_k(t) x at t = 0, size NumStates(). k < NumSymmetries().
  virtual void SymmetryGenerator(int /*k*/, const Vec& x, const Vec& /*u*/, Vec* g) const {
    g->setZero(x.size());
  }
  // y = S_k(t) x (t in radians). k < NumSymmetries().
  virtual void ApplySymmetry(int /*k*/, double /*t*/, const Vec& x, const Vec& /*u*/, Vec* y) const { *y = x; }
};

}  // namespace snapthread
