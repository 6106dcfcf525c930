// snapthread-bench: speed against accuracy.
//
//  * accuracy   each standard sweep with a snap, per method / cutoff / iteration budget:
//               updates per second against force and state error versus the tight
//               reference trace (and the chatter count), with the Pareto front.
//  * scaling    thread3d hand-speed update rate against n, per method and linear-algebra
//               backend, with a fitted log-log slope (the seed measured n^-1.9).
//  * service    pose -> force-model round trip and tick lateness of a real server +
//               device pair on loopback (read from the device's --summary JSON).
//  * advisor    "model no more than a scene needs": the smallest n and the cheapest
//               method / cutoff / budget meeting a scene's targets.
//
// Rates are wall-clock over whole EquilibriumTracker::Update calls (solve, forces and
// stiffness); every measurement is repeated and reported as median and spread because
// the machine is shared.
#pragma once

#include <functional>
#include <ostream>
#include <string>
#include <vector>

#include "solvers/registry.h"
#include "stability.h"

namespace snapthread {

// ---------------------------------------------------------------- statistics

// Median and spread of repeated measurements.
struct Spread {
  double median = 0.0, min = 0.0, max = 0.0;
  int count = 0;
};
Spread Summarize(std::vector<double> values);

// Least-squares fit of log10 y = intercept + slope log10 x (a power law y = a x^slope).
// Points with x <= 0 or y <= 0 are ignored; fewer than two usable points give
// points < 2 and slope 0.
struct PowerLawFit {
  double slope = 0.0;
  double intercept = 0.0;  // log10 a
  double r2 = 0.0;
  int points = 0;
  double At(double x) const;
};
PowerLawFit FitPowerLaw(const std::vector<double>& x, const std::vector<double>& y);

// Speed/accuracy points: higher rate and lower error are better.
struct ParetoPoint {
  double rate_hz = 0.0;
  double error = 0.0;
};
// Indices of the non-dominated points (no other point is at least as fast and at least
// as accurate, and strictly better in one), sorted by rate ascending. Of exact
// duplicates the first is kept.
std::vector<int> ParetoFront(const std::vector<ParetoPoint>& points);

// ---------------------------------------------------------------- timed sweeps

// A sweep run from a fresh tracker each time (the reset is not timed); a repetition
// repeats it until it has lasted `min_time_s`. The trace of the first run (for the error
// against a reference) and the rate of every repetition (updates after the resets
// divided by their wall time).
struct TimedSweep {
  std::vector<SweepRow> rows;
  Spread rate_hz;
};
TimedSweep TimeSweep(const Scene& scene, const std::vector<Vec>& controls, int repetitions, double min_time_s = 0.0);

// ---------------------------------------------------------------- rod speed

// Updates per second along scenes/rod_greenhill.yaml's path (2000 steps) at each n,
// logged one line per n (the rod's targets: n = 10 >= 50 k, n = 100 >= 10 k).
struct RodSpeedRow {
  int n = 0;
  Spread rate_hz;
};
std::vector<RodSpeedRow> RunRodSpeedBench(const std::string& scenes_dir, const std::vector<int>& ns,
                                          int repetitions, std::ostream& log);

// ---------------------------------------------------------------- accuracy

struct AccuracyOptions {
  std::vector<std::string> sweeps = {"zeeman_folds", "cusp_folds", "curve2d_snap", "thread3d_loop"};
  std::vector<std::string> methods = SolverRegistry::Global().Names();  // registered solver names
  std::vector<double> cutoffs = {1e-4, 1e-6, 1e-8, 1e-10};
  std::vector<int> budgets = {1, 2, 3, 5, 10, 0};  // 0 = unlimited
  int repetitions = 3;
  double min_time_s = 0.05;  // per repetition (short sweeps are repeated)
  int substeps = 10;  // reference: fine steps per row (as the stability suite)
};

struct AccuracyRow {
  std::string sweep;
  std::string method;  // a registered solver name
  double cutoff = 0.0;
  int budget = 0;
  Spread rate_hz;
  double force_scale = 1.0;  // the model's ForceScale()
  StabilityRow stability;    // errors, chatter, snaps, cost per update
  bool pareto = false;       // on the front of its sweep (rate vs relative rms force error)
  // rms |F - F_ref| / force_scale over the rows more than kSnapMargin rows away from every
  // snap of the trace or the reference: the accuracy of following a branch, without the
  // few rows where a snap one update early or late dominates the rms.
  double force_error_rel_rms_regular = 0.0;
  // The solve's stopping rule: the cutoff ladder stops on ||E_x|| < cutoff alone (force
  // tolerance 0: an explicit cutoff keeps its meaning); the default-settings point stops on
  // the certified force error, force_tolerance of the force scale, with the scene's cutoff
  // as a ceiling and its iteration budget.
  double force_tolerance = 0.0;
  bool default_settings = false;
  // The certified force error (SweepRow::force_error, docs/accuracy.md) / force scale over
  // the rows that carry one: rms and max; rows without one (-1) counted.
  double certified_rel_rms = 0.0, certified_rel_max = 0.0;
  int rows_without_estimate = 0;
  double RelativeForceErrorRms() const { return stability.force_error_rms / force_scale; }
};
constexpr int kSnapMargin = 2;
// The rms force error over rows away from snaps (see AccuracyRow), relative to `scale`.
double RegularRowsForceError(const std::vector<SweepRow>& trace, const std::vector<SweepRow>& ref, double scale);

std::vector<AccuracyRow> RunAccuracyBench(const std::string& scenes_dir, const AccuracyOptions& options,
                                          std::ostream* progress);
// Marks `pareto` per sweep.
void MarkParetoFronts(std::vector<AccuracyRow>* rows);
void WriteAccuracyCsv(const std::vector<AccuracyRow>& rows, std::ostream& out);
void PrintAccuracyTable(const std::vector<AccuracyRow>& rows, bool pareto_only, std::ostream& out);

// ---------------------------------------------------------------- scaling

struct ScalingOptions {
  std::vector<int> ns = {5, 10, 20, 50, 100, 200, 500, 1000, 2000};
  std::vector<std::string> methods = SolverRegistry::Global().Names();  // registered solver names
  std::vector<std::string> backends = {"auto", "banded", "cholmod", "dense"};
  int repetitions = 3;
  double min_sample_s = 0.15;       // timed updates per repetition last at least this
  int min_updates = 50;
  // Larger n is skipped for a method/backend once an update took longer than this.
  double max_update_us = 20000.0;
  double cutoff = 1e-6;
  // false (the set-up): n segments of the base scene's L, the thread grows with n.
  // true: the base scene's total length for every n (ResizeChain), the hand step stays
  // 0.002 L_base: the same physical thread, finer discretisations.
  bool fixed_length = false;
  double hand_step = 0.0;  // model units per update; 0 = 0.002 x the scene's segment length
};

struct ScalingRow {
  std::string method;  // a registered solver name
  std::string backend;
  int n = 0;
  Spread rate_hz;
  int updates = 0;                 // timed updates per repetition
  double iterations_per_update = 0.0;
  double max_residual = 0.0;       // largest ||E_x|| after a timed update
  int snaps = 0;                   // should be 0: the path stays away from folds
};

// The hand-speed scene: thread3d with n segments of the base scene's segment length L
// (fixed_length: n segments of the base scene's total length, see ResizeChain), no grip
// direction, grasp at (0.9, 0.1, 0.05) x the total length, the given cutoff, unlimited
// iterations (each update converges).
Scene HandSpeedScene(const Scene& thread3d_base, int n, const std::string& method, const std::string& backend, double cutoff,
                     bool fixed_length = false);
// Control of hand-speed update i: y moves `step` per update (0: 0.002 L), back and forth
// over +-0.05 x the total length (a triangle wave) so long runs stay near the start.
void HandSpeedControl(const Scene& scene, long i, Vec* u, double step = 0.0);
ScalingRow TimeHandSpeed(const Scene& scene, const ScalingOptions& options);

std::vector<ScalingRow> RunScalingBench(const std::string& scenes_dir, const ScalingOptions& options,
                                        std::ostream* progress);
struct ScalingFit {
  std::string method;  // a registered solver name
  std::string backend;
  PowerLawFit all;     // over every measured n
  PowerLawFit large;   // over n >= 100 (the asymptotic cost)
};
std::vector<ScalingFit> FitScaling(const std::vector<ScalingRow>& rows);
void WriteScalingCsv(const std::vector<ScalingRow>& rows, std::ostream& out);
void PrintScalingTable(const std::vector<ScalingRow>& rows, const std::vector<ScalingFit>& fits, std::ostream& out);
// The targets (higher-order / auto: n = 10, 100, 1000 rates, slope, cost relative
// to newton), each reported as met or not from the measured rows.
void PrintScalingTargets(const std::vector<ScalingRow>& rows, const std::vector<ScalingFit>& fits, std::ostream& out);

// ---------------------------------------------------------------- service

struct ServiceOptions {
  std::string bin_dir;      // holds snapthread-server and snapthread-device
  std::string scenes_dir;
  std::vector<std::string> scenes = {"curve2d_snap", "thread3d_loop"};
  double duration_s = 10.0;
  int repetitions = 3;
  std::string lcm_url = "udpm://239.255.76.67:7667?ttl=0";
  std::string work_dir;     // logs and summaries
};

struct ServiceRun {
  std::string scene;
  bool ok = false;
  std::string error;
  double round_trip_us_p50 = 0.0, round_trip_us_p99 = 0.0;
  double lateness_us_p50 = 0.0, lateness_us_p99 = 0.0;
  double tick_rate_hz = 0.0;
  double server_update_rate_hz = 0.0, server_solve_us_p50 = 0.0, server_solve_us_p99 = 0.0;
};

// Number field `key` of a flat JSON object; false when missing or not a number.
bool JsonNumber(const std::string& json, const std::string& key, double* value);
// Runs server + device once (unique session); never throws.
ServiceRun RunServiceOnce(const ServiceOptions& options, const std::string& scene, int index);
std::vector<ServiceRun> RunServiceBench(const ServiceOptions& options, std::ostream* progress);
void WriteServiceCsv(const std::vector<ServiceRun>& runs, std::ostream& out);
void PrintServiceTable(const std::vector<ServiceRun>& runs, std::ostream& out);

// ---------------------------------------------------------------- advisor

// The same chain with n segments and the same total length n l: l' = n l / n',
// bending and stretching scaled by l / l' (curve2d: EI = beta l and EA ~ 2 gamma l stay;
// thread3d the same ratios). Zeeman and cusp are returned unchanged.
Scene ResizeChain(const Scene& scene, int n);
bool IsChain(const Scene& scene);
// The scene's grasp path at hand speed: each leg cut into steps of at most 0.002 model
// units (and 0.5 degrees of grip turn); all legs use the largest count (as the standard
// sweeps do).
std::vector<Vec> HandSpeedPath(const Scene& scene);

struct AdvisorOptions {
  std::vector<int> n_ladder = {5, 8, 10, 15, 20, 30, 50, 80};
  int reference_n = 0;  // 0: 2 x max(the scene's n, the ladder's largest); rungs >= it are dropped
  std::vector<std::string> methods = SolverRegistry::Global().Names();  // registered solver names
  std::vector<double> cutoffs = {1e-4, 1e-6, 1e-8, 1e-10};
  std::vector<int> budgets = {1, 2, 3, 5, 10, 0};
  int repetitions = 3;
  double min_time_s = 0.05;  // per repetition (short sweeps are repeated)
  int substeps = 4;       // reference trace: fine steps per row
  // Iteration cap of the tight (newton-ls, cutoff 1e-10) solves of the reference and the
  // model-error rungs: from n ~ 200 up, round-off keeps ||E_x|| near 1e-10 and an
  // unlimited budget would spend the 10000-iteration safety cap on every update.
  int tight_max_iterations = 30;
  // Overrides of the scene's targets (0 = use the scene's).
  double target_force_error = 0.0;
  double target_rate_hz = 0.0;
  // Path used for the advice (empty: HandSpeedPath(scene)).
  std::vector<Vec> path;
};

struct AdviceCandidate {
  int n = 0;
  std::string method;  // a registered solver name
  double cutoff = 0.0;
  int budget = 0;
  double rate_hz = 0.0;       // median updates per second
  double force_error = 0.0;   // rms |F - F_ref| / ForceScale along the path
  int spurious_reversals = 0;
  bool MeetsError(double target) const { return force_error <= target; }
  bool MeetsRate(double target) const { return rate_hz >= target; }
  // Both targets, and no chatter: a force that reverses spuriously is not acceptable
  // however small its rms error.
  bool Acceptable(double target_error, double target_rate) const {
    return MeetsError(target_error) && MeetsRate(target_rate) && spurious_reversals == 0;
  }
};

struct ModelErrorRow {
  int n = 0;
  double force_error = 0.0;  // tight solve of the n-segment model against the reference
};

struct Advice {
  bool found = false;
  AdviceCandidate choice;
  double target_force_error = 0.0, target_rate_hz = 0.0;
  int reference_n = 0;
  std::vector<ModelErrorRow> model_errors;    // the ladder as far as it was climbed
  std::vector<AdviceCandidate> candidates;    // every configuration timed
  std::string message;                        // why this choice / why none
};

// Like ReferenceTrace (newton-ls, cutoff 1e-10, `substeps` fine steps per row) with an
// iteration cap per update instead of an unlimited budget.
std::vector<SweepRow> TightTrace(const Scene& scene, const std::vector<Vec>& controls, int substeps,
                                 int max_iterations);

// Index of the cheapest acceptable candidate (both targets, no chatter), -1 if none is:
// the fastest, where rates within kRateTieFraction of the fastest count as equal (noise)
// and the lowest force error among them wins.
constexpr double kRateTieFraction = 0.05;
int SelectCheapest(const std::vector<AdviceCandidate>& candidates, double target_force_error, double target_rate_hz);

// Throws std::invalid_argument when the scene states no targets and none are given.
Advice Advise(const Scene& scene, const AdvisorOptions& options, std::ostream* progress);
void PrintAdvice(const Advice& advice, std::ostream& out);

// ---------------------------------------------------------------- contact scaling

// On the scaling chart: self-contact's E + E_x + E_xx (broad and narrow
// phase) on a close helix of n segments, whose active pairs grow like n
// (contact_scaling.cc). Evaluations per second, median over repetitions.
struct ContactScalingRow {
  int n = 0;
  Spread rate_hz;
  int active_pairs = 0;
  int candidate_pairs = 0;  // what the broad phase handed to the narrow phase
};
std::vector<ContactScalingRow> RunContactScaling(const std::vector<int>& ns, int repetitions, double min_sample_s);
void WriteContactScalingCsv(const std::vector<ContactScalingRow>& rows, std::ostream& out);
// Over the rows with n >= min_n (small n: no pair near contact, nothing to fit).
PowerLawFit FitContactScaling(const std::vector<ContactScalingRow>& rows, int min_n = 100);

// ---------------------------------------------------------------- machine / charts

// "nproc N, CPU <model>, <UTC date>".
std::string MachineDescription();
// Runs gnuplot on a script file; false when gnuplot fails.
bool RunGnuplot(const std::string& script_path);
// gnuplot scripts (pngcairo, noenhanced) for the charts; they read the CSVs written
// next to them.
std::string ParetoGnuplot(const std::vector<AccuracyRow>& rows, const std::string& csv_dir, const std::string& png);
// With contact rows, each panel also draws self-contact's evaluation rate (its CSV,
// contact_scaling.csv, written next to the others).
std::string ScalingGnuplot(const std::vector<ScalingRow>& rows, const std::vector<ScalingFit>& fits,
                           const std::string& csv_dir, const std::string& png, bool fixed_length = false,
                           const std::vector<ContactScalingRow>& contact = {});

}  // namespace snapthread
