// snapthread-bench's logic on tiny inputs (issue 6): the power-law fit, the Pareto
// front, chain resizing, the hand-speed paths, JSON reading, and the advisor's choice.
// No timed assertions: rates are only checked to be consistent with the choice made.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "bench.h"
#include "path.h"
#include "models/models.h"
#include "test_util.h"

namespace snapthread {
namespace {

TEST(BenchStats, SummarizeGivesMedianAndSpread) {
  const Spread odd = Summarize({5.0, 1.0, 3.0});
  EXPECT_EQ(odd.count, 3);
  EXPECT_DOUBLE_EQ(odd.median, 3.0);
  EXPECT_DOUBLE_EQ(odd.min, 1.0);
  EXPECT_DOUBLE_EQ(odd.max, 5.0);
  EXPECT_DOUBLE_EQ(Summarize({4.0, 1.0, 2.0, 10.0}).median, 3.0);
  EXPECT_EQ(Summarize({}).count, 0);
}

TEST(BenchStats, PowerLawFitRecoversAKnownLaw) {
  for (double slope : {-1.9, -1.0, 0.5}) {
    std::vector<double> x, y;
    for (double n : {5.0, 10.0, 20.0, 50.0, 100.0, 1000.0}) {
      x.push_back(n);
      y.push_back(3e5 * std::pow(n, slope));
    }
    const PowerLawFit f = FitPowerLaw(x, y);
    EXPECT_EQ(f.points, 6);
    EXPECT_NEAR(f.slope, slope, 1e-12);
    EXPECT_NEAR(f.intercept, std::log10(3e5), 1e-10);
    EXPECT_NEAR(f.r2, 1.0, 1e-12);
    EXPECT_NEAR(f.At(40.0), 3e5 * std::pow(40.0, slope), 1e-8 * 3e5 * std::pow(40.0, slope));
  }
}

TEST(BenchStats, PowerLawFitIgnoresUnusablePointsAndNeedsTwo) {
  // A zero rate (a skipped point) must not poison the fit.
  const PowerLawFit f = FitPowerLaw({10, 100, 0, 1000, 50}, {1e4, 1e3, 5.0, 1e2, 0.0});
  EXPECT_EQ(f.points, 3);
  EXPECT_NEAR(f.slope, -1.0, 1e-12);
  EXPECT_LT(FitPowerLaw({10}, {1}).points, 2);
  EXPECT_LT(FitPowerLaw({10, 10}, {1, 2}).points, 2);  // no spread in x: no slope
  // Noisy data: the slope is the least-squares one, between the extremes.
  const PowerLawFit g = FitPowerLaw({1, 10, 100}, {1, 0.2, 0.01});
  EXPECT_LT(g.slope, -0.7);
  EXPECT_GT(g.slope, -1.3);
  EXPECT_LT(g.r2, 1.0);
}

TEST(BenchPareto, FrontKeepsOnlyNonDominatedPointsSortedByRate) {
  // rate, error
  const std::vector<ParetoPoint> p = {
      {100, 1e-3},   // 0 front (most accurate)
      {1000, 1e-2},  // 1 front
      {500, 1e-2},   // 2 dominated by 1 (slower, same error)
      {2000, 1e-1},  // 3 front (fastest)
      {800, 5e-3},   // 4 front
      {90, 2e-3},    // 5 dominated by 0
      {800, 5e-3},   // 6 exact duplicate of 4: only the first is kept
      {1500, 2e-1},  // 7 dominated by 3
  };
  EXPECT_EQ(ParetoFront(p), (std::vector<int>{0, 4, 1, 3}));
  EXPECT_TRUE(ParetoFront({}).empty());
  EXPECT_EQ(ParetoFront({{1, 1}}), std::vector<int>{0});
}

TEST(BenchPareto, MarkParetoFrontsIsPerSweep) {
  std::vector<AccuracyRow> rows(4);
  rows[0].sweep = rows[1].sweep = "a";
  rows[2].sweep = rows[3].sweep = "b";
  rows[0].rate_hz.median = 10;
  rows[0].stability.force_error_rms = 1.0;
  rows[1].rate_hz.median = 20;
  rows[1].stability.force_error_rms = 0.5;  // dominates row 0
  // In sweep b, a slow point with a large error would be dominated by sweep a's rows,
  // but fronts are per sweep.
  rows[2].rate_hz.median = 1;
  rows[2].stability.force_error_rms = 5.0;
  rows[3].rate_hz.median = 0.5;
  rows[3].stability.force_error_rms = 1.0;
  MarkParetoFronts(&rows);
  EXPECT_FALSE(rows[0].pareto);
  EXPECT_TRUE(rows[1].pareto);
  EXPECT_TRUE(rows[2].pareto);
  EXPECT_TRUE(rows[3].pareto);
}

TEST(BenchChains, ResizeKeepsLengthAndContinuumStiffness) {
  const Scene s = testing::SceneFile("curve2d_snap.yaml");
  const double total = s.params.Integer("n") * s.params.Number("segment_length");
  const double force_scale = MakeModel(s.params)->ForceScale();
  for (int n : {5, 20, 37}) {
    const Scene r = ResizeChain(s, n);
    EXPECT_EQ(r.params.Integer("n"), n);
    EXPECT_NEAR(r.params.Integer("n") * r.params.Number("segment_length"), total, 1e-12);
    EXPECT_NEAR(r.params.Number("bending") * r.params.Number("segment_length"), s.params.Number("bending") * s.params.Number("segment_length"), 1e-12);
    EXPECT_NEAR(r.params.Number("stretching") * r.params.Number("segment_length"), s.params.Number("stretching") * s.params.Number("segment_length"), 1e-9);
    // Forces stay comparable across n.
    EXPECT_NEAR(MakeModel(r.params)->ForceScale(), force_scale, 1e-12 * force_scale);
  }
  const Scene z = testing::SceneFile("zeeman.yaml");
  EXPECT_EQ(ResizeChain(z, 40).params.values, z.params.values);  // not a chain: unchanged
  EXPECT_FALSE(IsChain(z));
  EXPECT_TRUE(IsChain(s));
}

TEST(BenchPaths, HandSpeedPathMatchesTheStandardSweeps) {
  const Scene curve = testing::SceneFile("curve2d_snap.yaml");
  const auto p = HandSpeedPath(curve);
  ASSERT_EQ(p.size(), 8001u);  // two legs of 8 units at 0.002 per update
  for (size_t i = 1; i < p.size(); ++i) EXPECT_LE((p[i] - p[i - 1]).norm(), 0.002 + 1e-12);
  const Scene loop = testing::SceneFile("thread3d_loop.yaml");
  const auto q = HandSpeedPath(loop);
  EXPECT_EQ(q.size(), (loop.path.size() - 1) * 60 + 1);  // 30 degree legs at 0.5 degrees
}

TEST(BenchPaths, HandSpeedControlMovesSlowlyAndStaysNearTheStart) {
  const Scene base = testing::SceneFile("thread3d_loop.yaml");
  const Scene s = HandSpeedScene(base, 40, "higher-order", "banded", 1e-6);
  EXPECT_FALSE(s.params.Bool("grip_direction"));
  ASSERT_EQ(s.grasp_start.size(), 3);
  const double total = 40 * base.params.Number("segment_length");
  EXPECT_NEAR(s.grasp_start[0], 0.9 * total, 1e-12);
  Vec u, prev;
  HandSpeedControl(s, 0, &prev);
  EXPECT_NEAR((prev - s.grasp_start).norm(), 0.0, 1e-12);
  double lo = prev[1], hi = prev[1];
  for (long i = 1; i < 20000; ++i) {
    HandSpeedControl(s, i, &u);
    EXPECT_LE((u - prev).norm(), 0.002 * base.params.Number("segment_length") + 1e-9);
    lo = std::min(lo, u[1]);
    hi = std::max(hi, u[1]);
    prev = u;
  }
  EXPECT_NEAR(hi - s.grasp_start[1], 0.05 * total, 0.003);
  EXPECT_NEAR(s.grasp_start[1] - lo, 0.05 * total, 0.003);
}

TEST(BenchPaths, FixedLengthHandSpeedSceneKeepsTheThread) {
  const Scene base = testing::SceneFile("thread3d_loop.yaml");
  const double total = base.params.Integer("n") * base.params.Number("segment_length");
  for (int n : {5, 40, 400}) {
    const Scene s = HandSpeedScene(base, n, "newton", "auto", 1e-6, true);
    EXPECT_EQ(s.params.Integer("n"), n);
    EXPECT_FALSE(s.params.Bool("grip_direction"));
    EXPECT_NEAR(s.params.Integer("n") * s.params.Number("segment_length"), total, 1e-12);
    EXPECT_NEAR(s.params.Number("bending") * s.params.Number("segment_length"), base.params.Number("bending") * base.params.Number("segment_length"), 1e-9);
    EXPECT_NEAR(s.grasp_start[0], 0.9 * total, 1e-12);
    Vec u0, u1;
    HandSpeedControl(s, 0, &u0, 0.002 * base.params.Number("segment_length"));
    HandSpeedControl(s, 1, &u1, 0.002 * base.params.Number("segment_length"));
    EXPECT_NEAR((u1 - u0).norm(), 0.002 * base.params.Number("segment_length"), 1e-12);  // the hand's step, not l's
  }
}

TEST(BenchScaling, HandSpeedUpdatesConvergeWithoutSnapping) {
  const Scene base = testing::SceneFile("thread3d_loop.yaml");
  ScalingOptions o;
  o.repetitions = 2;
  o.min_sample_s = 0.0;
  o.min_updates = 100;
  for (const char* m : {"newton", "higher-order"}) {
    const ScalingRow r = TimeHandSpeed(HandSpeedScene(base, 8, m, "auto", 1e-6), o);
    EXPECT_EQ(r.n, 8);
    EXPECT_EQ(r.updates, 100);
    EXPECT_EQ(r.rate_hz.count, 2);
    EXPECT_GT(r.rate_hz.min, 0.0);
    EXPECT_EQ(r.snaps, 0);
    EXPECT_LT(r.max_residual, 1e-6);
    EXPECT_GE(r.iterations_per_update, 1.0);
  }
}

TEST(BenchTiming, TimedSweepRecordsTheSameTraceAsRunSweep) {
  Scene s = testing::SceneFile("curve2d_snap.yaml");
  SweepSpec spec;
  spec.from = Vec(2);
  spec.to = Vec(2);
  spec.from << 9.0, 3.0;
  spec.to << 9.0, 3.8;  // through the snap at Y = 3.41
  spec.steps = 100;
  const auto controls = SweepControls(s, spec);
  auto tracker = MakeTracker(s);
  const auto plain = RunSweep(tracker.get(), controls);
  const TimedSweep t = TimeSweep(s, controls, 3, 0.0);
  ASSERT_EQ(t.rows.size(), plain.size());
  EXPECT_EQ(t.rate_hz.count, 3);
  EXPECT_GT(t.rate_hz.min, 0.0);
  int snaps = 0;
  for (size_t i = 0; i < plain.size(); ++i) {
    EXPECT_EQ(t.rows[i].step, static_cast<int>(i));
    EXPECT_EQ((t.rows[i].force - plain[i].force).norm(), 0.0) << "row " << i;
    EXPECT_EQ(t.rows[i].probe, plain[i].probe);
    EXPECT_EQ(t.rows[i].snapped, plain[i].snapped);
    EXPECT_EQ(t.rows[i].iterations, plain[i].iterations);
    snaps += t.rows[i].snapped;
  }
  EXPECT_EQ(snaps, 1);
  // A minimum time per repetition repeats the sweep, it does not change the trace.
  const TimedSweep longer = TimeSweep(s, controls, 1, 0.02);
  EXPECT_EQ(longer.rate_hz.count, 1);
  EXPECT_EQ((longer.rows.back().force - plain.back().force).norm(), 0.0);
}

TEST(BenchTiming, RegularRowsLeaveOutRowsNearSnaps) {
  std::vector<SweepRow> ref(20), trace(20);
  for (int i = 0; i < 20; ++i) {
    ref[i].force = Vec::Zero(2);
    trace[i].force = Vec::Constant(2, 0.0);
    trace[i].force[0] = 0.1;  // a uniform error of 0.1 ...
  }
  ref[10].snapped = true;
  trace[11].snapped = true;  // ... and a snap one row late: a large error at row 10
  trace[10].force[0] = 50.0;
  // Rows 8..13 are within kSnapMargin = 2 of a snap; the rest carry the uniform 0.1.
  EXPECT_NEAR(RegularRowsForceError(trace, ref, 2.0), 0.1 / 2.0, 1e-12);
  // Without snaps every row counts, the late one too.
  ref[10].snapped = trace[11].snapped = false;
  EXPECT_NEAR(RegularRowsForceError(trace, ref, 2.0), std::sqrt((19 * 0.01 + 2500.0) / 20) / 2.0, 1e-12);
}

TEST(BenchService, JsonNumberReadsFlatFields) {
  const std::string j = "{\n  \"backend\": \"virtual-hand\",\n  \"round_trip_us_p50\": 412.5,\n"
                        "  \"round_trip_us_p99\": 1.2e3,\n  \"realtime\": false\n}\n";
  double v = 0;
  ASSERT_TRUE(JsonNumber(j, "round_trip_us_p50", &v));
  EXPECT_DOUBLE_EQ(v, 412.5);
  ASSERT_TRUE(JsonNumber(j, "round_trip_us_p99", &v));
  EXPECT_DOUBLE_EQ(v, 1200.0);
  EXPECT_FALSE(JsonNumber(j, "lateness_us_p50", &v));
  EXPECT_FALSE(JsonNumber(j, "backend", &v));
}

TEST(BenchService, MissingBinariesAreReportedNotThrown) {
  ServiceOptions o;
  o.bin_dir = "/nonexistent";
  o.scenes_dir = testing::SourceDir() + "/scenes";
  o.work_dir = ::testing::TempDir();
  const ServiceRun r = RunServiceOnce(o, "curve2d_snap", 0);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.error.find("missing"), std::string::npos) << r.error;
}

AdviceCandidate Cand(int n, const std::string& m, double rate, double err) {
  AdviceCandidate c;
  c.n = n;
  c.method = m;
  c.rate_hz = rate;
  c.force_error = err;
  return c;
}

TEST(BenchAdvisor, SelectCheapestPicksTheFastestAcceptableCandidate) {
  std::vector<AdviceCandidate> c = {
      Cand(10, "newton", 9e4, 0.2),         // 0 fastest, too inaccurate
      Cand(10, "newton-ls", 5e4, 0.01),
      Cand(10, "higher-order", 7e4, 0.04),   // 2 the answer
      Cand(10, "higher-order", 7.2e4, 0.06), // 3 faster, misses the error target
      Cand(10, "newton-ls", 900, 0.001),  // 4 too slow
      Cand(10, "newton", 8e4, 0.03),        // 5 fast and accurate enough, but chatters
  };
  c[5].spurious_reversals = 3;
  EXPECT_EQ(SelectCheapest(c, 0.05, 1000), 2);
  EXPECT_EQ(SelectCheapest(c, 0.5, 1000), 0);
  EXPECT_EQ(SelectCheapest(c, 0.005, 1000), -1);  // only the slow one is that accurate
  EXPECT_EQ(SelectCheapest(c, 0.005, 800), 4);
  EXPECT_EQ(SelectCheapest(c, 0.05, 1e6), -1);
  c[5].spurious_reversals = 0;
  EXPECT_EQ(SelectCheapest(c, 0.05, 1000), 5);  // without the chatter it is the fastest
  // Rates within kRateTieFraction are a tie (measurement noise): the more accurate wins.
  EXPECT_EQ(SelectCheapest({Cand(5, "newton", 1e3, 0.03), Cand(5, "newton", 0.97e3, 0.02)}, 0.05, 10), 1);
  EXPECT_EQ(SelectCheapest({Cand(5, "newton", 1e3, 0.03), Cand(5, "newton", 0.9e3, 0.02)}, 0.05, 10), 0);
}

// A small strip: 6 segments (resized by the advisor), compressed and lifted a little (no snap), 120 updates.
Scene SmallStrip() {
  return ParseScene(R"(
name: small_strip
model: curve2d
params: {n: 6, segment_length: 1.0, bending: 1.0, stretching: 100.0}
grasp:
  start: [5.4, 0.2]
  path: [[5.4, 0.2], [5.4, 0.44]]
solver: {method: higher-order, cutoff: 1.0e-6, max_iterations: 10}
)",
                    "<small_strip>");
}

AdvisorOptions SmallOptions() {
  AdvisorOptions o;
  // Below n = 8 this strip's coarse models buckle into visibly different shapes (model
  // errors 0.09 / 0.32 / 0.33 for n = 3 / 4 / 6): the ladder starts where the error falls.
  o.n_ladder = {8, 12, 16, 24};
  o.reference_n = 48;
  o.methods = {"newton", "higher-order"};
  o.cutoffs = {1e-4, 1e-8};
  o.budgets = {1, 0};
  o.repetitions = 1;
  o.min_time_s = 0.0;
  o.substeps = 2;
  return o;
}

TEST(BenchAdvisor, PicksTheSmallestModelAndCheapestConfigurationOrReportsNone) {
  const Scene scene = SmallStrip();
  EXPECT_THROW(Advise(scene, SmallOptions(), nullptr), std::invalid_argument);  // no targets

  // Impossible accuracy: the whole ladder is climbed, nothing is timed, none is found.
  AdvisorOptions o = SmallOptions();
  o.target_force_error = 1e-14;
  o.target_rate_hz = 1.0;
  const Advice none = Advise(scene, o, nullptr);
  EXPECT_FALSE(none.found);
  EXPECT_FALSE(none.message.empty());
  ASSERT_EQ(none.model_errors.size(), 4u);
  EXPECT_TRUE(none.candidates.empty());
  EXPECT_EQ(none.reference_n, 48);
  // Finer chains approach the reference.
  EXPECT_LT(none.model_errors[3].force_error, 0.5 * none.model_errors[0].force_error);
  const double e12 = none.model_errors[1].force_error, e16 = none.model_errors[2].force_error;
  ASSERT_LT(e16, e12);

  // A target between the n=12 and n=16 model errors (with room for the solver's own
  // error): n = 16 is the smallest model that can meet it.
  o.target_force_error = e16 + 0.5 * (e12 - e16);
  o.target_rate_hz = 1.0;  // any configuration is fast enough
  const Advice a = Advise(scene, o, nullptr);
  ASSERT_TRUE(a.found) << a.message;
  EXPECT_EQ(a.choice.n, 16);
  EXPECT_LE(a.choice.force_error, o.target_force_error);
  EXPECT_GE(a.choice.rate_hz, o.target_rate_hz);
  ASSERT_EQ(a.model_errors.size(), 3u);  // 8, 12, 16
  EXPECT_GT(a.model_errors[0].force_error, o.target_force_error);
  EXPECT_GT(a.model_errors[1].force_error, o.target_force_error);
  EXPECT_EQ(a.choice.spurious_reversals, 0);
  // The choice is the fastest acceptable configuration in the evidence (up to the tie
  // margin for noise).
  ASSERT_EQ(a.candidates.size(), 2u * 2u * 2u);
  for (const auto& c : a.candidates) {
    EXPECT_EQ(c.n, 16);
    if (c.Acceptable(o.target_force_error, o.target_rate_hz)) {
      EXPECT_LE(c.rate_hz, a.choice.rate_hz / (1.0 - kRateTieFraction));
    }
  }

  // The same accuracy at an unreachable rate: reported, with the evidence.
  o.target_rate_hz = 1e12;
  const Advice slow = Advise(scene, o, nullptr);
  EXPECT_FALSE(slow.found);
  EXPECT_EQ(slow.candidates.size(), 8u);
  EXPECT_NE(slow.message.find("updates/s"), std::string::npos) << slow.message;
}

TEST(BenchAdvisor, UsesTheTargetsTheSceneStates) {
  Scene scene = SmallStrip();
  scene.target_force_error = 10.0;  // anything goes
  scene.target_rate_hz = 1.0;
  AdvisorOptions o = SmallOptions();
  const Advice a = Advise(scene, o, nullptr);
  ASSERT_TRUE(a.found) << a.message;
  EXPECT_EQ(a.choice.n, 8);  // the coarsest model meets so loose a target
  EXPECT_DOUBLE_EQ(a.target_force_error, 10.0);
  EXPECT_DOUBLE_EQ(a.target_rate_hz, 1.0);
}

}  // namespace
}  // namespace snapthread

namespace snapthread {
namespace {

// The path benchmark's floor must be a real factor + solve of the same system.
TEST(BenchPath, PlainBandedFloorSolvesTheThreadHessian) {
  const Scene base = LoadScene(std::string(SNAPTHREAD_TEST_SOURCE_DIR) + "/scenes/thread3d_loop.yaml");
  const Scene scene = Thread3dPathScene(base, 12, PathOptions{});
  const auto model = MakeModel(scene.params);
  const std::vector<Vec> controls = Thread3dPathControls(scene, 4);
  ASSERT_EQ(controls.size(), 5u);
  EXPECT_NEAR(controls.back()[1] - controls.front()[1], 0.3, 1e-15);
  EXPECT_NEAR(controls.back()[2] - controls.front()[2], 0.2, 1e-15);
  const Vec x = model->InitialState(controls[0]);
  SparseMatrix h = model->HessianPattern();
  model->Hessian(x, controls[0], &h);
  const Vec rhs = Vec::LinSpaced(model->NumStates(), -1.0, 2.0);
  Vec solution;
  ASSERT_TRUE(PlainBandedSolve(h, model->HessianBandwidth(), rhs, &solution));
  EXPECT_LT((h * solution - rhs).norm() / rhs.norm(), 1e-9);
}

// The accuracy columns: coverage counts rows whose estimate is at least the true error
// (a row without an estimate, -1, never covers), row 0 (the reset) is left out, and the
// errors are relative to the force scale.
TEST(BenchPath, AccuracyComparesEveryRowWithTheReference) {
  auto f = [](double v) { return Vec::Constant(3, v); };
  const std::vector<Vec> reference = {f(0.0), f(1.0), f(1.0), f(1.0), f(1.0)};
  const std::vector<Vec> forces = {f(9.0), f(1.0 + 2e-3), f(1.0 - 4e-3), f(1.0 + 1e-3), f(1.0)};
  const std::vector<double> estimates = {0.0, 8e-3, 8e-3, -1.0, 0.0};
  const PathAccuracy a = CompareWithReference(forces, estimates, reference, 2.0, 1.5e-3);
  ASSERT_TRUE(a.ran);
  EXPECT_EQ(a.rows, 4);
  EXPECT_NEAR(a.error_max, 2e-3, 1e-15);       // row 2: 4e-3 / 2 (row 0's 9 is the reset)
  EXPECT_NEAR(a.error_median, 7.5e-4, 1e-15);  // of 1e-3, 2e-3, 5e-4, 0
  EXPECT_NEAR(a.estimate_max, 4e-3, 1e-15);
  EXPECT_EQ(a.rows_without_estimate, 1);
  EXPECT_DOUBLE_EQ(a.coverage, 0.75);          // rows 1, 2, 4 covered; row 3 has none
  EXPECT_NEAR(a.ratio_median, 3.0, 1e-9);      // 4 and 2 (row 4: both 0, no ratio)
  EXPECT_EQ(a.rows_over_target, 1);
  // With the reference's own certified errors, rows whose difference is within them are
  // not resolved: row 4 (0 <= anything) and row 1 (1e-3 <= 3e-3 / 2).
  const PathAccuracy b = CompareWithReference(forces, estimates, reference, 2.0, 1.5e-3, {0.0, 3e-3, 0.0, 0.0, 0.0});
  EXPECT_EQ(b.rows_resolved, 2);
  EXPECT_DOUBLE_EQ(b.coverage_resolved, 0.5);  // row 2 covered, row 3 has no estimate
}

// On a short n = 10 path at the default settings every row's force is within the target
// of its own state polished to round-off, the certified estimate covers it, and the
// independent sweep (cutoff 1e-11, force tolerance 1e-8, no iteration limit) ends
// converged on every row and agrees within the target.
TEST(BenchPath, DefaultSettingsMeetTheAccuracyTargetOnAShortPath) {
  const Scene base = LoadScene(std::string(SNAPTHREAD_TEST_SOURCE_DIR) + "/scenes/thread3d_loop.yaml");
  const PathOptions o;
  const Scene scene = Thread3dPathScene(base, 10, o);
  const std::vector<Vec> controls = Thread3dPathControls(scene, 40);
  auto tracker = MakeTracker(scene);
  tracker->Reset(controls[0]);
  std::vector<Vec> states{tracker->state()}, forces{tracker->last().force};
  std::vector<double> estimates{tracker->last().summary.force_error};
  for (size_t i = 1; i < controls.size(); ++i) {
    const TrackResult& r = tracker->Update(controls[i]);
    states.push_back(tracker->state());
    forces.push_back(r.force);
    estimates.push_back(r.summary.force_error);
  }
  const PathAccuracy a = MeasurePathAccuracy(scene, controls, states, forces, estimates, o);
  ASSERT_TRUE(a.ran);
  EXPECT_EQ(a.rows, 40);
  EXPECT_EQ(a.reference_not_converged, 0);
  EXPECT_EQ(a.rows_over_target, 0) << a.error_max;
  EXPECT_EQ(a.rows_without_estimate, 0);
  EXPECT_GE(a.coverage, 0.95) << a.coverage;
  EXPECT_GT(a.estimate_median, 0.0);
  EXPECT_LE(a.sweep_error_max, o.force_target) << a.sweep_error_max;
}

#ifdef SNAPTHREAD_HAVE_CERES
// Ceres' residuals carry the same energy as the model: 1/2 sum r^2 + shift = E(x, u)
// to round-off, at straight, bent and random states (and with a reference bend B).
TEST(BenchPath, CeresResidualsGiveTheModelsEnergy) {
  ASSERT_TRUE(CeresBuilt());
  const Scene base = LoadScene(std::string(SNAPTHREAD_TEST_SOURCE_DIR) + "/scenes/thread3d_loop.yaml");
  std::mt19937 rng(5);
  std::normal_distribution<double> noise(0.0, 0.2);
  for (int n : {3, 10, 100}) {
    Scene scene = Thread3dPathScene(base, n, PathOptions{});
    if (n == 10) scene.params.Set("reference_bend", 0.3);
    const auto model = MakeModel(scene.params);
    const Vec u = scene.grasp_start;
    for (int trial = 0; trial < 4; ++trial) {
      Vec x = model->InitialState(u);
      if (trial > 0) {
        for (int i = 0; i < x.size(); ++i) x[i] += trial * noise(rng);
      }
      const double e = model->Energy(x, u);
      const double c = CeresEnergy(scene, x, u);
      EXPECT_NEAR(c, e, 1e-12 * std::max(1.0, std::abs(e))) << "n = " << n << ", trial " << trial;
    }
  }
}

// Every Ceres setting of the ladder runs, stays on the project's equilibria of a short
// n = 10 path (after row 0), and a tighter cutoff brings its forces closer to the
// project's: the accuracy ladder can only decide anything if this holds.
TEST(BenchPath, CeresSettingsFollowTheProjectAndTightenWithTheCutoff) {
  const Scene base = LoadScene(std::string(SNAPTHREAD_TEST_SOURCE_DIR) + "/scenes/thread3d_loop.yaml");
  PathOptions o;
  o.cutoff = 1e-10;  // the project's rows as the judge: far below both Ceres cutoffs
  const Scene scene = Thread3dPathScene(base, 10, o);
  const std::vector<Vec> controls = Thread3dPathControls(scene, 20);
  auto tracker = MakeTracker(scene);
  tracker->Reset(controls[0]);
  std::vector<Vec> states{tracker->state()}, forces{tracker->last().force};
  for (size_t i = 1; i < controls.size(); ++i) {
    forces.push_back(tracker->Update(controls[i]).force);
    states.push_back(tracker->state());
  }
  ASSERT_FALSE(CeresSolverNames(10).empty());
  for (const std::string& solver : CeresSolverNames(10)) {
    CeresSetting loose, tight;
    loose.solver = tight.solver = solver;
    loose.cutoff = 1e-6;
    tight.cutoff = 1e-8;
    const CeresPathResult a = RunCeresPath(scene, controls, states, forces, loose);
    const CeresPathResult b = RunCeresPath(scene, controls, states, forces, tight);
    ASSERT_TRUE(a.ran && b.ran) << solver << ": " << a.note << " / " << b.note;
    EXPECT_EQ(b.rows_not_converged, 0) << solver;
    EXPECT_EQ(b.rows_other_equilibrium, 0) << solver;
    EXPECT_EQ(b.rows_saddle, 0) << solver;
    EXPECT_LT(b.force_error_max, a.force_error_max) << solver;
    EXPECT_LE(b.force_error_median, b.force_error_max) << solver;
  }
  CeresSetting bad;
  bad.solver = "lm-no-such-solver";
  EXPECT_FALSE(RunCeresPath(scene, controls, states, forces, bad).ran);
}
#endif

}  // namespace
}  // namespace snapthread
