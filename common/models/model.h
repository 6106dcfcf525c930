// The energy model interface: every system of the seed (zeeman, cusp, curve2d,
// thread3d) and the rod is a smooth energy E(x, u) of internal state x and controls u
// (the grasp). Model holds what every model has; what only some can do (self-contact,
// symmetries, lagged history, material frames, band assembly, grasp torque) is an
// optional capability, a small interface of its own reached through an accessor below.
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

#include <string_view>

#include <Eigen/Core>

#include "numeric/types.h"

namespace snapthread {

class BandAssemblyCapability;    // models/band_assembly_capability.h
class ContactCapability;         // models/contact_capability.h
class FramesCapability;          // models/frames_capability.h
class GraspTorqueCapability;     // models/grasp_torque_capability.h
class HistoryCapability;         // models/history_capability.h
class SymmetryCapability;        // models/symmetry_capability.h

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
  // 2 for planar models (u = (X, Y)), 3 for thread3d and the rod.
  virtual int SpatialDimension() const = 0;

  virtual double Energy(const Vec& x, const Vec& u) const = 0;
  // E_x, size NumStates().
  virtual void Gradient(const Vec& x, const Vec& u, Vec* g) const = 0;
  // E_xx with the pattern of HessianPattern(). A model with self-contact changes that
  // pattern (the blocks of the segment pairs near contact, models/contact_terms.h) inside
  // a Hessian evaluation, rarely; HessianPatternVersion() then moves, Hessian() gives
  // *h the new structure, and a solver analyses its factorisation again. The version is
  // part of the Hessian's contract, not a capability: a fixed pattern is version 0
  // forever, which is the default.
  virtual const SparseMatrix& HessianPattern() const = 0;
  virtual int HessianPatternVersion() const { return 0; }
  virtual void Hessian(const Vec& x, const Vec& u, SparseMatrix* h) const = 0;

  // Fused evaluations (GradientAndHessian, EnergyGradientAndHessian and, below,
  // ControlDerivatives) are no capabilities: every model has them, as the separate calls
  // (the defaults, the same values). They are the solvers' and the tracker's hot path, a
  // model overrides one only to make one pass over its terms instead of two or three, and
  // a default keeps that path one virtual call for every model.
  //
  // E_x and E_xx at one state, the same values as Gradient() and Hessian() (the solvers
  // call this where both are needed).
  virtual void GradientAndHessian(const Vec& x, const Vec& u, Vec* g, SparseMatrix* h) const {
    Gradient(x, u, g);
    Hessian(x, u, h);
  }
  // E(x, u), E_x and E_xx at one state, the same values as Energy(), Gradient() and
  // Hessian() (to the last bit); returns E (a converged solve needs all three at its warm
  // start).
  virtual double EnergyGradientAndHessian(const Vec& x, const Vec& u, Vec* g, SparseMatrix* h) const {
    GradientAndHessian(x, u, g, h);
    return Energy(x, u);
  }
  // E_u, size NumControls(). The force on the grasp is F = -E_u (envelope theorem, §2.3.4).
  virtual void ControlGradient(const Vec& x, const Vec& u, Vec* eu) const = 0;
  // E_xu, NumStates() x NumControls() (dense: only a few rows are non-zero).
  virtual void MixedHessian(const Vec& x, const Vec& u, Mat* exu) const = 0;
  // E_uu, NumControls() x NumControls().
  virtual void ControlHessian(const Vec& x, const Vec& u, Mat* euu) const = 0;
  // E_u, E_xu and E_uu at one state, the same values as the three above (fused: the
  // tracker's force and K).
  virtual void ControlDerivatives(const Vec& x, const Vec& u, Vec* eu, Mat* exu, Mat* euu) const {
    ControlGradient(x, u, eu);
    MixedHessian(x, u, exu);
    ControlHessian(x, u, euu);
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

  // --- optional capabilities ------------------------------------------------------
  // What only some models can do is asked through small interfaces, each with its own
  // header (models/models.h includes them all). A caller asks once (the solver and the
  // tracker when they are built, the sweep before its loop) and keeps the pointer for the
  // model's lifetime: null means the model has no such capability, and the caller does
  // what that means (a whole step, no history to move, no frames to draw, ...).
  //
  // Self-contact: continuous collision bounds and the active pairs (thread3d and the rod
  // with contact enabled).
  virtual const ContactCapability* contact() const { return nullptr; }
  // Continuous symmetries of E (thread3d's roll about the clamp–grasp axis).
  virtual const SymmetryCapability* symmetry() const { return nullptr; }
  // Lagged data moved by the tracker at each accepted state (the rod's reference frames).
  virtual HistoryCapability* history() { return nullptr; }
  // Material frames for drawing (the rod).
  virtual const FramesCapability* frames() const { return nullptr; }
  // E, E_x and E_xx straight into band storage (the chains and the rod).
  virtual const BandAssemblyCapability* band_assembly() const { return nullptr; }
  // The torque of a grasp that holds its orientation (the rod).
  virtual const GraspTorqueCapability* grasp_torque() const { return nullptr; }
};

}  // namespace snapthread
