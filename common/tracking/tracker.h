// EquilibriumTracker: follows the quasi-static equilibrium of a model as the grasp
// moves, and gives the force on the grasp with its implicit derivative. This is the
// one object the sweep tool, the stability suite, the benchmarks and the server share.
#pragma once

#include <functional>
#include <memory>
#include <vector>

#include "models/contact_capability.h"
#include "models/history_capability.h"
#include "models/model.h"
#include "solvers/solver.h"

namespace snapthread {

struct TrackResult {
  SolverSummary summary;
  // F = -E_u at the equilibrium (envelope theorem, §2.3.4 / (2.16-2.17)).
  Vec force;
  // K = dF/du = -(E_uu - E_ux E_xx^-1 E_xu) by implicit differentiation (2.14-2.15),
  // from the factorisation the solver already holds. Near a fold the one near-zero
  // eigenvalue is floored (stiffness_regularized = true) so K stays finite; it is
  // never NaN or infinite.
  Mat stiffness;
  bool stiffness_regularized = false;
  double energy = 0.0;
  double probe = 0.0;
  // The state left the branch it followed at this update (a snap-through).
  bool snapped = false;
};

class EquilibriumTracker {
 public:
  // Throws std::invalid_argument for invalid options.
  EquilibriumTracker(std::unique_ptr<Model> model, const SolverOptions& options);

  // Start again from the model's InitialState(u), solved to the cutoff with an
  // unlimited budget (a reset must start on an equilibrium). Where that reaches no stable
  // equilibrium (not converged, or a saddle it could not leave) and a start
  // continuation is set, the start follows one along the family instead.
  const TrackResult& Reset(const Vec& u);

  // Models along t in [0, 1] whose member at t = 1 is this tracker's model (the scene's
  // solver.start_continuation: some parameters scaled by t, e.g. a rod's coil memory).
  // Reset's fallback: natural-parameter continuation from the initial state at t = 0 to
  // t = 1, each step the start solve from the last step's equilibrium, a step halved
  // where it reaches no stable equilibrium; the lagged data (the rod's frames) follow
  // the accepted states. Empty: no fallback.
  using ModelFamily = std::function<std::unique_ptr<Model>(double t)>;
  void SetStartContinuation(ModelFamily family) { start_family_ = std::move(family); }
  // Number of continuation steps the last Reset took (0: the direct start was stable).
  int start_continuation_steps() const { return start_continuation_steps_; }
  // Sub-steps the last Update's retry (RetryFailedUpdate) took; 0: none.
  int substeps() const { return substeps_; }
  // Start again from a saved equilibrium x at controls u (a server checkpoint): the
  // model's lagged data is moved to x first (AcceptState), then x is solved again with the
  // tracking solver, warm-started at x, so the state stays on its branch and the
  // factorisation, force and K are current. Throws std::invalid_argument for sizes that
  // do not match the model or a non-finite x or u.
  const TrackResult& Resume(const Vec& x, const Vec& u);
  // One control update: predictor, solve within the budget, force and stiffness.
  const TrackResult& Update(const Vec& u);

  // The same controls under another name: u must give the model the same energy as
  // control() does (a grasp's rotation vector moved to another representative of its
  // rotation, server/grasp_poses.h). The state, the model's lagged data and the last
  // result stay; the predictor starts again here (its tangent and secant are in the old
  // names, so the next Update starts from the current state). Throws
  // std::invalid_argument for a size that does not match or a non-finite u.
  void RelabelControls(const Vec& u);

  // Switch method / budget / cutoff without losing the state.
  void SetOptions(const SolverOptions& options);

  const Model& model() const { return *model_; }
  const SolverOptions& options() const { return options_; }
  const Vec& state() const { return x_; }
  const Vec& control() const { return u_; }
  const TrackResult& last() const { return result_; }
  // Self-contact of the current state: the active pairs and their closest points (the
  // server's solver_status_t.contacts and thread_shape_t.contacts; allocates).
  // None for a model without self-contact.
  std::vector<contact::ContactPoint> ActiveContacts() const {
    return contact_ == nullptr ? std::vector<contact::ContactPoint>{} : contact_->ActiveContacts(x_, u_);
  }
  // A state change larger than this (max norm, model units) against the predicted
  // state counts as a jump to another branch (default 0.1; scenes set 0.1 l).
  void SetSnapThreshold(double t) { snap_threshold_ = t; }

 private:
  // A snap the snap minimiser left unfinished at its own iteration cap (linear-solver-
  // failed after a snap with |E_x| > 1e3 cutoff, no time budget: the update may take
  // what the snap needs) goes on
  // from its last accepted, energy-decreasing state with more solves, at most
  // kSnapRetries; the summary counts them all.
  void FinishUnfinishedSnap(const Vec& u);
  // An update left with no usable state after FinishUnfinishedSnap (linear-solver-
  // failed, non-finite; no time budget) is retried (common/tracking/substep.cc): the
  // failed state solved at controls further along the step, u + a (u - u_prev) for
  // a = 1, 2, 4, where the snap it crawled through finishes, and the equilibrium found
  // there followed back to u (ContinueInSubsteps). True when it reached an equilibrium
  // at u; otherwise the failed state is solved once more at u. The summary counts all
  // the work.
  bool RetryFailedUpdate(const Vec& u);
  // Natural-parameter continuation of the equilibrium *x at u0 to u1 in sub-steps (a
  // quarter of the way first, halved where one fails, down to 1/64), the lagged data
  // following each sub-step's equilibrium; false if a sub-step fails at the smallest
  // length. *last is the last solve; the work is added to *total.
  bool ContinueInSubsteps(const Vec& u0, const Vec& u1, Vec* x, SolverSummary* total, SolverSummary* last);
  // Reset's start solve of `model` from *x: newton-ls, unlimited, then off a saddle
  // along its negative mode (at most 8 times).
  SolverSummary SolveStart(const Model& model, const Vec& u, Vec* x) const;
  // Reset's fallback (SetStartContinuation): on success x_ is the family's equilibrium
  // at t = 1 and the model's lagged data are those of the state before (the caller
  // solves there again, SolveAndStartHere); on failure x_ and the lagged data are the
  // direct start's.
  bool StartByContinuation(const Vec& u);
  // The end of Reset and Resume: solve at (x_, u_) with the tracking solver and make that
  // state the start of the path (no predictor history, force and K, lagged model data).
  const TrackResult& SolveAndStartHere();
  // Shortens the predicted state change x_pred_ - x_ until the node motion from (x_, u_)
  // to (x_pred_, u) passes no segment through another (self-contact;
  // ContactCapability::MaxMotionFraction). Nothing to do without self-contact.
  void LimitPrediction(const Vec& u);
  // x_pred_ -= the tangent step E_xx^-1 E_xu (u - u_) (capped at 5 snap thresholds);
  // false, x_pred_ unchanged, when there is no factorisation or the step is not finite.
  bool TangentPrediction(const Vec& u);
  void ComputeForces();

  // Lagged model data (the rod's reference frames): forgotten at a reset, moved to every
  // accepted state. Nothing to move for a model without history.
  void ResetModelHistory();
  void AcceptModelState();

  std::unique_ptr<Model> model_;
  // The model's capabilities the tracker uses, asked once (null: the model has none).
  HistoryCapability* const history_;
  const ContactCapability* const contact_;
  SolverOptions options_;
  std::unique_ptr<EquilibriumSolver> solver_;
  Vec x_, x_prev_, u_, u_prev_;
  Vec snap_origin_;  // the predicted state of the update where the current snap began
  bool have_prev_ = false;
  // The solver's factorisation (or sol_, tangent_in_sol_) gives E_xx^-1 E_xu of the
  // current state.
  bool have_tangent_ = false;
  bool tangent_in_sol_ = false;  // sol_ holds E_xx^-1 E_xu (kept across SetOptions)
  double snap_threshold_ = 0.1;
  ModelFamily start_family_;
  int start_continuation_steps_ = 0;
  int substeps_ = 0;
  double lambda_ref_ = -1.0;
  TrackResult result_;
  // scratch
  Vec eu_, scratch_, x_pred_, du_, rhs_, vexu_;
  Mat exu_, euu_, sol_, quad_;
};

}  // namespace snapthread
