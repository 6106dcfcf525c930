// SolverBase: the machinery every Newton-type equilibrium method shares.
#pragma once

#include <chrono>
#include <memory>
#include <vector>

#include "models/band_assembly_capability.h"
#include "models/contact_capability.h"
#include "solvers/eigen_tracking.h"
#include "solvers/solver.h"
#include "solvers/symmetry_orbits.h"

namespace snapthread {

// What every method shares: the model, one Hessian with its fixed pattern and its
// factorisation (symbolic analysis done once), a second factorisation for modified
// matrices with the same pattern (shifted or restricted), the tracked lowest eigenpair,
// the loop head and tail, and the globalised fallbacks. All of it lives in a private
// workspace sized once in the constructor (no allocation per solve after the first);
// a method reaches it only through the functions below.
class SolverBase : public EquilibriumSolver {
 public:
  SolverBase(const Model& model, const SolverOptions& options);
  const std::string& method() const override { return options_.method; }
  void Reset() override;
  const SymmetricLinearSolver* Factorization() const override;
  // How many times E_xx's pattern changed under this solver (self-contact; SyncPattern).
  int PatternChanges() const { return pattern_changes_; }
  const Vec& LowestEigenvector() const override { return ws_.eig.vector(); }

 protected:
  const Model& model() const { return model_; }
  // The model's collision bound on the step from x to x + dx (self-contact,
  // ContactCapability::MaxStepFraction); 1, the whole step, for a model without.
  double MaxStepFraction(const Vec& x, const Vec& dx, const Vec& u) const {
    return contact_ == nullptr ? 1.0 : contact_->MaxStepFraction(x, dx, u);
  }
  const SolverOptions& options() const { return options_; }
  int num_states() const { return n_; }

  // --- a solve's frame ---------------------------------------------------------------
  // Starts a solve from the warm start x (remembered as the last finite state).
  // Returns false, with summary->termination = kInvalidInput and a message, when x or
  // u has the wrong size or is not finite: then the method must return at once.
  bool BeginSolve(const Vec& u, const Vec& x, SolverSummary* s);
  // After BeginSolve: when the last update ran out of time inside a snap (kSnapping),
  // carries the snap on from x (the snap's last state) with the minimiser, concludes
  // and returns true: the method returns s at once. Otherwise false.
  bool ContinueSnap(const Vec& u, Vec* x, SolverSummary* s);
  // Loop head shared by every method: stops on a non-finite residual (restoring the last
  // finite state), on convergence (Converged), when the budget is spent or when |E_x|
  // has stalled (at the gradient's round-off: converged, StopAtRoundOff); otherwise
  // counts the iteration, remembers the state and returns true. The workspace gradient
  // holds E_x(x), |E_x| = r.
  bool NextIteration(double r, const Vec& u, Vec* x, SolverSummary* s);
  // Loop tail: restore a non-finite state, Finish(); for globalised methods leave a
  // saddle (LeaveSaddle); with finish_snap_on_spent_budget, a budget spent on an
  // indefinite E_xx finishes the snap (the followed minimum is gone, DESIGN.md #4);
  // then the status (DecideStatus) and the reference eigenvalue.
  void Conclude(const Vec& u, Vec* x, SolverSummary* s, bool leave_saddles,
                bool finish_snap_on_spent_budget = false);

  // --- accuracy (accuracy.cc, docs/accuracy.md) ---------------------------------------
  // The convergence test at x, |E_x| = r (the workspace gradient): r < cutoff and, with
  // a force tolerance (ForceTarget() > 0), the certified force error at x within it. That
  // factorises E_xx at x, which the iteration that follows reuses (FactorAt).
  bool Converged(double r, const Vec& x, const Vec& u, SolverSummary* s);
  // max(force_tolerance * ForceScale, force_floor_n / newtons_per_model_force), model
  // force units; 0 when options.force_tolerance is 0 (the cutoff alone).
  double ForceTarget() const { return force_target_; }
  // Is |E_x| = r at x (workspace gradient = E_x(x)) at the gradient's round-off? Asked
  // where |E_x| stalls or a step is implausibly long, never on every iteration. The
  // floor is the change of E_x when every coordinate of x moves by one unit in its last
  // place (x is known to no better), one gradient evaluation; it is recorded in
  // s->round_off_floor.
  bool AtRoundOff(double r, const Vec& x, const Vec& u, SolverSummary* s);
  // Ends the solve as converged at round-off (termination kConverged, at_round_off).
  static void StopAtRoundOff(SolverSummary* s);
  // The certified force error at x with HessianFactor() at x (or next to it, kReuseStep)
  // and the workspace gradient = E_x(x): dx = E_xx^-1 E_x, the Newton correction (2.18),
  // moves the force by E_ux dx to first order (2.14-2.15); the estimate is a margin times
  // the larger of that and the force change to x - dx (curvature of E_u; where it
  // dominates, after a second correction), plus the force's round-off. -1 when the solve fails. Cached per factorisation and state.
  double ForceErrorFromFactor(const Vec& x, const Vec& u);
  // ForceErrorFromFactor's force change where the correction dx is long along a soft
  // mode: to x - dx - dx2 after a second correction (accuracy.cc); `first` where none.
  double SecondOrderForceChange(const Vec& u, double first);
  // No force tolerance, or the force error at x (as ForceErrorFromFactor) within it or
  // not estimable.
  bool ForceCertified(const Vec& x, const Vec& u);

  // --- gradient ----------------------------------------------------------------------
  // E_x(x, u) into the workspace gradient; returns its norm.
  double EvalGradient(const Vec& x, const Vec& u, SolverSummary* s);
  // E_x(x, u) into *g (a method's own vector); returns its norm.
  double EvalGradient(const Vec& x, const Vec& u, Vec* g, SolverSummary* s) const;
  // EvalGradient(x, u, s) at the warm start of a solve, where E_xx is always needed next
  // (by the first iteration, or by Finish() when the warm start has converged): the model
  // evaluates both in one pass, and the next FactorAt() at this x uses that E_xx.
  double EvalGradientAtStart(const Vec& x, const Vec& u, SolverSummary* s) { return EvalGradientAndHessian(x, u, s); }
  // The same at any iterate whose E_xx is needed next whatever |E_x| turns out to be
  // (after a step that was not tiny, kReuseStep: by the next iteration or by Finish()).
  // The factorisation of the last state is gone.
  double EvalGradientAndHessian(const Vec& x, const Vec& u, SolverSummary* s);
  // The last TakeNewtonStep() was tiny (kReuseStep): Finish() may keep the factorisation.
  bool LastStepTiny() const { return factor_before_tiny_step_; }
  const Vec& Gradient() const { return ws_.g; }
  // A method's own E_x(x, u) becomes the workspace gradient (swapped with *g, which gets
  // the old one); returns its norm. For a trial state that became the iterate.
  double AdoptGradient(Vec* g) {
    ws_.g.swap(*g);
    return ws_.g.norm();
  }

  // --- Hessian and its factorisations ------------------------------------------------
  // Assembles E_xx at x and factorises it (HessianFactor()).
  LinearSolverStatus FactorAt(const Vec& x, const Vec& u, SolverSummary* s);
  // E_xx at the state of HessianFactor() as a compressed matrix (evaluated here when
  // the factorisation was assembled in band storage, EnsureSparseHessian()).
  const SparseMatrix& Hessian() {
    EnsureSparseHessian();
    return ws_.h;
  }
  const SymmetricLinearSolver& HessianFactor() const { return *ws_.factor; }
  // A modified copy of E_xx (same pattern): ModifiedHessian() returns the copy with the
  // current values, the method edits its values, FactorModified() factorises it into
  // the second factorisation that SolveModified() uses.
  SparseMatrix& ModifiedHessian();
  LinearSolverStatus FactorModified(SolverSummary* s);
  LinearSolverStatus SolveModified(const Vec& b, Vec* x) const { return ws_.alt_factor->Solve(b, x); }

  // --- steps ---------------------------------------------------------------------------
  // The Newton step (2.18) d = E_xx^-1 E_x with HessianFactor() and Gradient().
  LinearSolverStatus ComputeNewtonStep() { return ws_.factor->Solve(ws_.g, &ws_.dx); }
  const Vec& NewtonStep() const { return ws_.dx; }
  // Takes x -= NewtonStep() (shortened by the model's collision bound, MaxStepFraction,
  // so no segment passes through another) and records whether it was small enough for Finish() to
  // keep using the factorisation (see kReuseStep in solver_base.cc).
  void TakeNewtonStep(const Vec& u, Vec* x);
  // Newton-ls step: inertia-corrected Newton direction + Armijo backtracking from x with
  // Gradient(). Returns false if no decrease could be found. An E_xx with more negative
  // pivots than at the last returned state is an inertia change: it marks s->snapped.
  bool GlobalizedStep(const Vec& u, Vec* x, SolverSummary* s);
  // Globalised minimisation to the cutoff past the iteration budget (a snap is finished
  // inside its control step, DESIGN.md #4). From a saddle, where the gradient vanishes,
  // it first leaves along the negative mode of E_xx (the side that lowers E).
  bool MinimizeFully(const Vec& u, Vec* x, SolverSummary* s);

  // --- lowest eigenpair ----------------------------------------------------------------
  // `iterations` steps of inverse iteration with HessianFactor(); the Rayleigh quotient.
  double UpdateEigenpair(int iterations);
  // Sets the deterministic start vector if none has been tracked yet.
  void EnsureEigenvector() { ws_.eig.EnsureInitialized(n_); }
  // lambda_0 at the last regular converged state (DESIGN.md #1); <= 0: none yet.
  double ReferenceLambda() const { return lambda_ref_; }

 private:
  using Clock = std::chrono::steady_clock;

  struct Workspace {
    SparseMatrix h, h_mod;
    std::unique_ptr<SymmetricLinearSolver> factor, alt_factor;
    std::vector<int> diag_index;  // position of (i,i) in h.valuePtr()
    SmallestEigenpair eig;
    std::unique_ptr<SymmetryOrbits> orbits;
    Vec g, dx, trial, last_good, dx_scratch;
    Vec g_band;   // E_x from a band assembly in FactorAt (not the iterate's gradient)
    Vec h_state;  // the state h was evaluated at by EvalGradientAtStart (hessian_ready_)
    Vec h_u;      // ... and its controls
    Vec factor_x;  // the state the valid factorisation was made at (FactorAt reuses it there)
    // Accuracy (accuracy.cc): the Newton correction, E_xu, the corrected state, E_u at
    // both ends, the force change, the state of the cached estimate; the round-off probe.
    Vec err_dx, err_x, err_eu0, err_eu1, err_df, err_state;
    Mat exu;
    Vec noise_x, noise_g;
  };

  // ws_.h := E_xx at ws_.h_state when the factorisation there was assembled in band
  // storage (sparse_stale_): the rare steps that edit or read E_xx entry by entry.
  void EnsureSparseHessian();
  // E_xx at x written into the factorisation's band by the model (E and E_x with it, the
  // energy kept as at the warm start): ws_.h_state = x, the compressed matrix stale.
  // false, nothing written, where the factorisation or the model cannot.
  bool AssembleBandAt(const Vec& x, const Vec& u);
  // After the model wrote ws_.h: when its pattern changed (self-contact, model.h), the
  // rest of the workspace follows it and both factorisations are analysed again.
  void SyncPattern();
  // x is bit for bit the state of EvalGradientAtStart's E_xx (ws_.h_state).
  bool AtHessianState(const Vec& x) const;
  bool BudgetLeft(const SolverSummary& s) const;
  // The time budget (options.max_time_us > 0) is spent: one steady_clock read per
  // iteration is the whole cost of the check.
  bool TimeSpent() const;
  int Budget() const;
  // Factorises E_xx + shift I into the second factorisation (the pattern has the diagonal).
  LinearSolverStatus FactorShifted(double shift, SolverSummary* s);
  // Final bookkeeping at the returned state: factorisation for implicit
  // differentiation, lowest eigenpair, inertia, residual, energy, timing.
  // gradient_current: the workspace gradient already holds E_x(x).
  void Finish(const Vec& x, const Vec& u, SolverSummary* s, bool gradient_current = false);
  // Moves x downhill along the model's symmetry orbits through it (a snap across a
  // symmetry axis rolls the state round the circle); true if it moved.
  bool MoveAlongSymmetries(const Vec& u, Vec* x);
  // After Finish(): a "converged" state with negative pivots is a saddle, not the
  // followed minimum. Leave it and minimise (counted as a snap); then Finish again.
  void LeaveSaddle(const Vec& u, Vec* x, SolverSummary* s);

  const Model& model_;
  // The model's capabilities the solver uses, asked once (null: the model has none).
  const ContactCapability* const contact_;
  const BandAssemblyCapability* const band_assembly_;
  const SolverOptions options_;
  const int n_;
  Workspace ws_;
  bool factor_valid_ = false;
  // The factorisation holds E_xx at the state before the last, tiny, plain Newton step:
  // Finish() may use it instead of factorising again (kReuseStep).
  bool factor_before_tiny_step_ = false;
  // ws_.h holds E_xx at ws_.h_state from EvalGradientAtStart, not yet factorised.
  bool hessian_ready_ = false;
  // The factor's band holds E_xx at ws_.h_state (direct assembly), not yet factorised.
  bool band_ready_ = false;
  // ws_.h is not E_xx at the factorised state: that is ws_.h_state's, assembled in band.
  bool sparse_stale_ = false;
  // h_state_energy_ is E at ws_.h_state (from EvalGradientAtStart, this solve).
  bool energy_ready_ = false;
  double h_state_energy_ = 0.0;
  int pattern_version_ = 0;  // the model's HessianPatternVersion() that ws_ follows
  int pattern_changes_ = 0;  // re-analyses so far (SyncPattern)
  bool alt_stale_ = false;   // alt_factor not analysed for the current pattern
  // ws_.factor holds a valid factorisation of E_xx at ws_.factor_x (FactorAt reuses it).
  bool factor_at_state_ = false;
  long factor_serial_ = 0;   // counts factorisations (and band overwrites)
  const double force_target_;  // ForceTarget()
  long err_serial_ = -1;     // factor_serial_ of the cached force error (at ws_.err_state)
  double err_value_ = -1.0;
  double lambda_ref_ = -1.0;     // lambda_0 at the last regular converged state
  // Negative pivots of E_xx at the last usable returned state: a factorisation with more
  // is an inertia change (the state left the followed minimum's basin, GlobalizedStep).
  int accepted_negative_pivots_ = 0;
  // MinimizeFully stopped at the time budget: the snap goes on at the next update.
  bool snap_in_progress_ = false;
  double best_residual_ = 0.0;   // stagnation tracking in NextIteration
  int stalled_iterations_ = 0;
  Clock::time_point start_;
};

}  // namespace snapthread
