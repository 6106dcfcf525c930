// Analytic derivatives of every model against central finite differences, one test body
// per model configuration (TEST_P), plus the no-allocation contract of the evaluation
// calls on presized outputs.
//
// Central differences with step h ~ 1e-6 have truncation error O(h²) ~ 1e-12 and
// round-off ~ eps |E| / h ~ 1e-9 relative to the derivatives checked here, so the
// relative-norm tolerance 1e-6 passes with margin while any wrong term (a missing
// factor, sign, transpose or chain-rule piece) is off by O(1).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <ostream>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "allocation_counter.h"
#include "finite_difference.h"
#include "models/models.h"
#include "models/rod_model.h"

namespace snapthread {
namespace {

struct Case {
  std::string name;
  ModelParams params;
};

// gtest prints parameters on failure: the name, not the object's bytes.
void PrintTo(const Case& c, std::ostream* os) { *os << c.name; }

std::vector<Case> AllCases() {
  std::vector<Case> cases;
  cases.push_back({"zeeman", {.model = "zeeman"}});
  cases.push_back({"cusp", {.model = "cusp"}});
  // Non-default lengths and stiffnesses so that a coefficient mix-up cannot cancel.
  for (int n : {2, 3, 5, 10, 23}) {
    cases.push_back({"curve2d_n" + std::to_string(n),
                     {.model = "curve2d",
                      .values = {{"n", n}, {"segment_length", 0.7}, {"bending", 1.3}, {"stretching", 40.0}}}});
  }
  for (bool grip : {false, true}) {
    for (int n : {2, 3, 5, 10, 17}) {
      if (grip && n < 3) continue;
      cases.push_back({"thread3d_n" + std::to_string(n) + (grip ? "_grip" : ""),
                       {.model = "thread3d",
                        .values = {{"n", n}, {"segment_length", 0.8}, {"bending", 2.1}, {"stretching", 60.0},
                                   {"reference_bend", 0.3}, {"grip_direction", grip}}}});
    }
  }
  // The rod: a ribbon (B2 != B1) with natural curvature in both directions.
  for (int n : {3, 5, 12}) {
    cases.push_back({"rod_n" + std::to_string(n),
                     {.model = "rod",
                      .values = {{"n", n}, {"length", 1.3}, {"stretch_stiffness", 80.0}, {"bend_stiffness", 1.1},
                                 {"bend_stiffness_2", 2.3}, {"twist_stiffness", 0.7}, {"natural_curvature", 0.4},
                                 {"natural_curvature_2", -0.3}}}});
  }
  // Self-contact (issue 15): capsules of radius 0.02 on edges of 0.1 with an activation
  // gap of 0.04, at curled states where several pairs are active (ContactPoints).
  for (const char* model : {"rod", "thread3d"}) {
    ModelParams p;
    p.model = model;
    p.Set("n", 14);
    if (p.model == "rod") {
      p.Set("length", 1.4);
      p.Set("twist_stiffness", 0.7);
    } else {
      p.Set("segment_length", 0.1);
    }
    p.Set("radius", 0.02);
    p.Set("contact", true);
    p.Set("contact_distance", 0.04);
    p.Set("contact_stiffness", 0.5);
    cases.push_back({std::string(model) + "_contact", p});
    if (p.model == "rod") {
      // No clamp: edge 0 held by a first grasp u[0..5], so pairs map through both.
      p.Set("clamp", false);
      cases.push_back({"rod_free_contact", p});
    }
  }
  return cases;
}

// A state/control pair to differentiate at.
struct Point {
  Vec x;
  Vec u;
};

bool HasContact(const ModelParams& p) { return p.Has("contact") && p.Bool("contact"); }

// States of a contact case: the free nodes on a curling random walk of edge-length steps
// (each direction turned by up to ~70 degrees from the last) from the clamp, kept when
// every pair that may touch is apart by more than 2r + d̂/10 and at least two pairs are
// active; the first point has one with the grasped end (E_u, E_xu, E_uu), and without a
// clamp the second one with the first grasp's edge 0 (its x_0, x_1 are controls).
std::vector<Point> ContactPoints(const Model& m, const ModelParams& p, int count, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const bool rod = p.model == "rod";
  const bool free = rod && p.Has("clamp") && !p.Bool("clamp");
  const int n = p.Integer("n");
  const double l = rod ? p.Number("length") / n : p.Number("segment_length");
  const double r = p.Number("radius"), dhat = p.Number("contact_distance");
  std::vector<Point> points;
  for (int attempt = 0; attempt < 200000 && static_cast<int>(points.size()) < count; ++attempt) {
    Eigen::Matrix3Xd nodes(3, n + 1);
    nodes.col(0).setZero();
    Eigen::Vector3d dir = Eigen::Vector3d::UnitX();
    nodes.col(1) = l * dir;
    for (int k = 2; k <= n; ++k) {
      dir = (dir + 1.2 * Eigen::Vector3d(unit(rng), unit(rng), unit(rng))).normalized();
      nodes.col(k) = nodes.col(k - 1) + l * dir;
    }
    Point pt;
    pt.u = Vec::Zero(m.NumControls());
    if (rod) {
      // The grasp holds the last edge: orientation φ with R(φ) e_x along it.
      const Eigen::Vector3d e = (nodes.col(n) - nodes.col(n - 1)).normalized();
      const Eigen::Vector3d axis = Eigen::Vector3d::UnitX().cross(e);
      const double angle = std::atan2(axis.norm(), e.x());
      // Without a clamp the first grasp (u[0..5] = 0) holds edge 0 along +x at the origin.
      const int end = free ? 6 : 0;
      pt.u.segment<3>(end) = nodes.col(n);
      if (axis.norm() > 1e-12) pt.u.segment<3>(end + 3) = angle * axis.normalized();
      pt.x = m.InitialState(pt.u);
      const auto& rm = dynamic_cast<const RodModel&>(m);
      for (int k = 2; k <= n - 2; ++k) pt.x.segment<3>(rm.NodeIndex(k)) = nodes.col(k);
      for (int j = 1; j <= n - 2; ++j) pt.x[rm.ThetaIndex(j)] = 0.3 * unit(rng);
    } else {
      pt.u = nodes.col(n);
      pt.x.resize(m.NumStates());
      pt.x[0] = nodes(0, 1);
      for (int k = 2; k <= n - 1; ++k) pt.x.segment<3>(1 + 3 * (k - 2)) = nodes.col(k);
    }
    const std::vector<contact::ContactPoint> active = m.contact()->ActiveContacts(pt.x, pt.u);  // a contact case
    int with_grasp = 0, with_start = 0;
    bool apart = true;
    for (const auto& c : active) {
      apart = apart && c.distance > 2 * r + 0.1 * dhat;
      with_grasp += c.segment_b >= (rod ? n - 2 : n - 1) ? 1 : 0;
      with_start += c.segment_a <= 1 ? 1 : 0;
    }
    const bool need_grasp = points.empty();
    const bool need_start = free && points.size() == 1;
    if (!apart || active.size() < 2 || (need_grasp && with_grasp == 0) || (need_start && with_start == 0))
      continue;
    points.push_back(pt);
  }
  return points;
}

// Random states: for chains, controls near a compressed chord (|chord| = 0.8 n l, random
// direction, out of plane too in 3D), a grip direction roughly along the chord with a
// non-unit length, and the InitialState perturbed by ~0.1 l per coordinate.
std::vector<Point> RandomPoints(const Model& model, const ModelParams& p, int count,
                                unsigned seed) {
  if (HasContact(p)) return ContactPoints(model, p, count, seed);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::vector<Point> points;
  for (int k = 0; k < count; ++k) {
    Point pt;
    pt.u.resize(model.NumControls());
    if (p.model == "zeeman") {
      pt.u << 1.5 * unit(rng), 2.25 + 1.75 * unit(rng);
      pt.x = Vec::Constant(1, 3.14 * unit(rng));
    } else if (p.model == "cusp") {
      pt.u << 2.0 * unit(rng), 2.0 * unit(rng);
      pt.x = Vec::Constant(1, 2.0 * unit(rng));
    } else if (p.model == "rod") {
      // The grasp 0.8 L from the clamp, tilted and rolled (|φ| up to ~1 rad), the nodes
      // and angles of the initial state perturbed by ~0.1 of an edge / radian.
      const double edge = p.Number("length") / p.Integer("n");
      pt.u << 0.8 * p.Number("length"), 0.2 * unit(rng), 0.2 * unit(rng), 0.6 * unit(rng),
          0.3 * unit(rng), 0.3 * unit(rng);
      pt.x = model.InitialState(pt.u);
      for (int i = 0; i < pt.x.size(); ++i) pt.x[i] += 0.1 * edge * unit(rng);
    } else {
      const double total = p.Integer("n") * p.Number("segment_length");
      Eigen::Vector3d dir(1.0, 0.4 * unit(rng), 0.4 * unit(rng));
      if (p.model == "curve2d") dir.z() = 0.0;
      dir.normalize();
      const Eigen::Vector3d chord = 0.8 * total * dir;
      pt.u.head(model.SpatialDimension()) = chord.head(model.SpatialDimension());
      if (GraspLayoutOf(p).grip_direction) {
        const Eigen::Vector3d d =
            1.7 * dir + 0.3 * Eigen::Vector3d(unit(rng), unit(rng), unit(rng));
        pt.u.tail<3>() = d;
      }
      pt.x = model.InitialState(pt.u);
      for (int i = 0; i < pt.x.size(); ++i) pt.x[i] += 0.1 * p.Number("segment_length") * unit(rng);
    }
    points.push_back(pt);
  }
  return points;
}

constexpr double kStep = 1e-6;
constexpr double kRelTol = 1e-6;

// |a - b| <= tol (|b| + floor): relative in norm, with a small absolute floor for blocks
// that are exactly zero (e.g. E_uu of the cusp, rows of E_xu away from the grasp).
::testing::AssertionResult RelClose(const Mat& analytic, const Mat& fd, double floor) {
  const double err = (analytic - fd).norm();
  const double bound = kRelTol * (fd.norm() + floor);
  if (err <= bound) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "error " << err << " > bound " << bound
                                       << "\nanalytic:\n" << analytic << "\nfinite difference:\n"
                                       << fd;
}

class ModelDerivativeTest : public ::testing::TestWithParam<Case> {
 protected:
  void SetUp() override { model_ = MakeModel(GetParam().params); }
  std::unique_ptr<Model> model_;
};

TEST_P(ModelDerivativeTest, SizesAndPatternAreConsistent) {
  const Model& m = *model_;
  const ModelParams& p = GetParam().params;
  if (p.model == "curve2d") {
    EXPECT_EQ(m.NumStates(), 2 * p.Integer("n") - 3);
    EXPECT_EQ(m.NumControls(), 2);
  } else if (p.model == "thread3d") {
    EXPECT_EQ(m.NumStates(), GraspLayoutOf(p).grip_direction ? 3 * p.Integer("n") - 7 : 3 * p.Integer("n") - 5);
    EXPECT_EQ(m.NumControls(), GraspLayoutOf(p).grip_direction ? 6 : 3);
  } else if (p.model == "rod") {
    EXPECT_EQ(m.NumStates(), 4 * p.Integer("n") - 11);  // nodes 2..n-2 and angles 1..n-2
    EXPECT_EQ(m.NumControls(), p.Has("clamp") && !p.Bool("clamp") ? 12 : 6);
  } else {
    EXPECT_EQ(m.NumStates(), 1);
    EXPECT_EQ(m.NumControls(), 2);
  }
  const SparseMatrix& pattern = m.HessianPattern();
  ASSERT_EQ(pattern.rows(), m.NumStates());
  ASSERT_EQ(pattern.cols(), m.NumStates());
  EXPECT_TRUE(pattern.isCompressed());
  // Structurally symmetric, and the advertised bandwidth is the pattern's.
  int bandwidth = 0;
  for (int col = 0; col < pattern.cols(); ++col) {
    for (SparseMatrix::InnerIterator it(pattern, col); it; ++it) {
      bandwidth = std::max(bandwidth, std::abs(static_cast<int>(it.row()) - col));
      bool found = false;
      for (SparseMatrix::InnerIterator jt(pattern, it.row()); jt; ++jt) found |= jt.row() == col;
      EXPECT_TRUE(found) << "(" << it.row() << "," << col << ") without its transpose";
    }
  }
  // Self-contact changes the pattern (the pairs near contact): no fixed bandwidth.
  EXPECT_EQ(m.HessianBandwidth(), HasContact(p) ? -1 : bandwidth);
  // O(n) non-zeros for chains: at most 3 nodes per term, so a row couples at most 5
  // nodes' coordinates (the rod: at most its band, 2 x 10 + 1 entries a row). With
  // self-contact too: before any evaluation no pair is near contact.
  const long per_row = p.model == "rod" ? 2L * bandwidth + 1 : 5L * m.SpatialDimension();
  EXPECT_LE(pattern.nonZeros(), per_row * m.NumStates());
}

TEST_P(ModelDerivativeTest, DerivativesMatchFiniteDifferences) {
  const Model& m = *model_;
  const ModelParams& p = GetParam().params;
  const std::vector<Point> points = RandomPoints(m, p, 4, 12345u);
  ASSERT_EQ(points.size(), 4u);
  for (const Point& pt : points) {
    const Vec& x = pt.x;
    const Vec& u = pt.u;
    ASSERT_TRUE(std::isfinite(m.Energy(x, u)));

    const test_support::ModelDerivatives exact = test_support::ReportedDerivatives(m, x, u);
    const test_support::ModelDerivatives fd = test_support::CentralDifferences(m, x, u, kStep);
    ASSERT_EQ(exact.e_x.size(), m.NumStates());
    ASSERT_EQ(exact.e_u.size(), m.NumControls());
    ASSERT_EQ(exact.e_xu.rows(), m.NumStates());
    ASSERT_EQ(exact.e_xu.cols(), m.NumControls());
    ASSERT_EQ(exact.e_uu.rows(), m.NumControls());
    ASSERT_EQ(exact.e_uu.cols(), m.NumControls());
    // Hessian() into an empty matrix: exactly HessianPattern()'s structure.
    SparseMatrix h;
    m.Hessian(x, u, &h);
    ASSERT_EQ(h.rows(), m.NumStates());
    const SparseMatrix& pattern = m.HessianPattern();
    ASSERT_EQ(h.nonZeros(), pattern.nonZeros());
    for (int j = 0; j <= h.cols(); ++j) ASSERT_EQ(h.outerIndexPtr()[j], pattern.outerIndexPtr()[j]);
    for (int k = 0; k < h.nonZeros(); ++k) ASSERT_EQ(h.innerIndexPtr()[k], pattern.innerIndexPtr()[k]);
    const Mat hd = Mat(h);
    EXPECT_LE((hd - hd.transpose()).norm(), 1e-12 * hd.norm()) << "E_xx not symmetric";

    EXPECT_TRUE(RelClose(exact.e_x, fd.e_x, 1e-6)) << "E_x";
    EXPECT_TRUE(RelClose(hd, fd.e_xx, 1e-6)) << "E_xx";
    EXPECT_TRUE(RelClose(exact.e_u, fd.e_u, 1e-6)) << "E_u";
    EXPECT_TRUE(RelClose(exact.e_xu, fd.e_xu, 1e-6)) << "E_xu";
    EXPECT_TRUE(RelClose(exact.e_uu, fd.e_uu, 1e-6)) << "E_uu";

    if (GraspLayoutOf(p).grip_direction) {
      // Only d/|d| enters: scaling d changes nothing, so E_d is orthogonal to d.
      const Eigen::Vector3d d = u.tail<3>();
      EXPECT_LE(std::abs(exact.e_u.tail<3>().dot(d)), 1e-9 * (exact.e_u.norm() + 1.0) * d.norm());
    }
  }
}

TEST_P(ModelDerivativeTest, PresizedOutputsAreReusedWithoutAllocation) {
  const Model& m = *model_;
  const Point pt = RandomPoints(m, GetParam().params, 1, 777u).front();
  SparseMatrix h = m.HessianPattern();
  Vec g(m.NumStates()), eu(m.NumControls());
  Mat exu(m.NumStates(), m.NumControls()), euu(m.NumControls(), m.NumControls());
  // Self-contact keeps broad-phase scratch that one warm-up call sizes, and its first
  // Hessian here gives the pattern the blocks of the pairs near contact (a new structure).
  if (HasContact(GetParam().params)) {
    m.Energy(pt.x, pt.u);
    m.Hessian(pt.x, pt.u, &h);
    m.ControlHessian(pt.x, pt.u, &euu);
  }
  const double* values = h.valuePtr();
  const int* inner = h.innerIndexPtr();
  const int* outer = h.outerIndexPtr();
  const double* g_data = g.data();
  const double* exu_data = exu.data();

  if (test_support::kCountsAllocations) {
    // Sanity check of the counter itself, so a broken interposition cannot pass silently.
    test_support::AllocationCounter sanity;
    { Vec scratch(1000); scratch.setZero(); }
    sanity.Stop();
    ASSERT_GE(sanity.mallocs(), 1) << "malloc counter is not counting";
  }
  // Band storage for the fused band assembly (models that write none, or whose pattern is
  // not a fixed band (self-contact: bandwidth -1), decline).
  const int b = m.HessianBandwidth();
  std::vector<double> band(static_cast<size_t>(m.NumStates()) * static_cast<size_t>(std::max(b, 0) + 1));
  test_support::AllocationCounter counter;
  double e = 0.0;
  for (int rep = 0; rep < 3; ++rep) {
    double e_band = 0.0;
    if (m.band_assembly() != nullptr &&
        m.band_assembly()->EnergyGradientAndBandHessian(pt.x, pt.u, &g, band.data(), b, &e_band))
      e += e_band;
    e += m.Energy(pt.x, pt.u);
    m.Gradient(pt.x, pt.u, &g);
    m.Hessian(pt.x, pt.u, &h);
    m.ControlGradient(pt.x, pt.u, &eu);
    m.MixedHessian(pt.x, pt.u, &exu);
    m.ControlHessian(pt.x, pt.u, &euu);
    m.GradientAndHessian(pt.x, pt.u, &g, &h);
    m.ControlDerivatives(pt.x, pt.u, &eu, &exu, &euu);
  }
  counter.Stop();
  EXPECT_EQ(counter.mallocs(), 0) << "evaluation allocated on presized outputs";
  EXPECT_TRUE(std::isfinite(e));
  EXPECT_EQ(h.valuePtr(), values);
  EXPECT_EQ(h.innerIndexPtr(), inner);
  EXPECT_EQ(h.outerIndexPtr(), outer);
  EXPECT_EQ(g.data(), g_data);
  EXPECT_EQ(exu.data(), exu_data);
  // And the values were written (not left at the pattern's zeros).
  EXPECT_GT(Mat(h).norm(), 0.0);
}

// The fused evaluations (one pass over the terms) give the separate ones' values to the
// last bit, and E_xx does not depend on what the matrix held before (the assembly stores
// each slot's first contribution instead of clearing): the solvers rely on both.
TEST_P(ModelDerivativeTest, FusedEvaluationsEqualSeparateOnesBitForBit) {
  const Model& m = *model_;
  for (const Point& pt : RandomPoints(m, GetParam().params, 3, 4242u)) {
    Vec g, g2;
    SparseMatrix h, h2 = m.HessianPattern();
    m.Gradient(pt.x, pt.u, &g);
    m.Hessian(pt.x, pt.u, &h);
    std::fill(h2.valuePtr(), h2.valuePtr() + h2.nonZeros(), std::numeric_limits<double>::quiet_NaN());
    m.GradientAndHessian(pt.x, pt.u, &g2, &h2);
    ASSERT_EQ(g2.size(), g.size());
    ASSERT_EQ(h2.nonZeros(), h.nonZeros());
    EXPECT_EQ(std::memcmp(g.data(), g2.data(), sizeof(double) * g.size()), 0) << "E_x";
    EXPECT_EQ(std::memcmp(h.valuePtr(), h2.valuePtr(), sizeof(double) * h.nonZeros()), 0) << "E_xx";
    m.Hessian(pt.x, pt.u, &h2);  // over the previous values: still the same
    EXPECT_EQ(std::memcmp(h.valuePtr(), h2.valuePtr(), sizeof(double) * h.nonZeros()), 0) << "E_xx again";

    // E with E_x and E_xx in one pass: Energy()'s value to the last bit.
    Vec g3;
    SparseMatrix h3 = m.HessianPattern();
    const double e = m.Energy(pt.x, pt.u);
    const double e3 = m.EnergyGradientAndHessian(pt.x, pt.u, &g3, &h3);
    EXPECT_EQ(std::memcmp(&e, &e3, sizeof e), 0) << "E: " << e << " vs " << e3;
    EXPECT_EQ(std::memcmp(g.data(), g3.data(), sizeof(double) * g.size()), 0) << "E_x with E";
    EXPECT_EQ(std::memcmp(h.valuePtr(), h3.valuePtr(), sizeof(double) * h.nonZeros()), 0) << "E_xx with E";

    Vec eu, eu2;
    Mat exu, exu2, euu, euu2;
    m.ControlGradient(pt.x, pt.u, &eu);
    m.MixedHessian(pt.x, pt.u, &exu);
    m.ControlHessian(pt.x, pt.u, &euu);
    m.ControlDerivatives(pt.x, pt.u, &eu2, &exu2, &euu2);
    ASSERT_EQ(eu2.size(), eu.size());
    ASSERT_EQ(exu2.rows(), exu.rows());
    ASSERT_EQ(exu2.cols(), exu.cols());
    ASSERT_EQ(euu2.rows(), euu.rows());
    EXPECT_EQ(std::memcmp(eu.data(), eu2.data(), sizeof(double) * eu.size()), 0) << "E_u";
    EXPECT_EQ(std::memcmp(exu.data(), exu2.data(), sizeof(double) * exu.size()), 0) << "E_xu";
    EXPECT_EQ(std::memcmp(euu.data(), euu2.data(), sizeof(double) * euu.size()), 0) << "E_uu";
  }
}

TEST_P(ModelDerivativeTest, WrongSizedOutputsAreResized) {
  const Model& m = *model_;
  const Point pt = RandomPoints(m, GetParam().params, 1, 99u).front();
  SparseMatrix h;  // empty: must receive the pattern
  Vec g, eu;
  Mat exu(7, 1), euu;
  m.Gradient(pt.x, pt.u, &g);
  m.Hessian(pt.x, pt.u, &h);
  m.ControlGradient(pt.x, pt.u, &eu);
  m.MixedHessian(pt.x, pt.u, &exu);
  m.ControlHessian(pt.x, pt.u, &euu);
  EXPECT_EQ(g.size(), m.NumStates());
  EXPECT_EQ(h.rows(), m.NumStates());
  EXPECT_EQ(h.nonZeros(), m.HessianPattern().nonZeros());
  EXPECT_EQ(eu.size(), m.NumControls());
  EXPECT_EQ(exu.rows(), m.NumStates());
  EXPECT_EQ(exu.cols(), m.NumControls());
  EXPECT_EQ(euu.rows(), m.NumControls());
  // Same values as with a presized matrix.
  SparseMatrix h2 = m.HessianPattern();
  m.Hessian(pt.x, pt.u, &h2);
  EXPECT_EQ((Mat(h) - Mat(h2)).norm(), 0.0);
}

TEST_P(ModelDerivativeTest, NodesProbeAndInitialStateAreConsistent) {
  const Model& m = *model_;
  const ModelParams& p = GetParam().params;
  const Point pt = RandomPoints(m, p, 1, 4242u).front();
  Eigen::Matrix3Xd nodes;
  m.NodePositions(pt.x, pt.u, &nodes);
  ASSERT_GE(nodes.cols(), 1);
  EXPECT_TRUE(nodes.allFinite());
  EXPECT_GT(m.ForceScale(), 0.0);
  if (p.model == "curve2d" || p.model == "thread3d") {
    ASSERT_EQ(nodes.cols(), p.Integer("n") + 1);
    EXPECT_EQ(nodes.col(0).norm(), 0.0);                       // p_0 clamped at 0
    EXPECT_EQ(nodes.col(1).tail<2>().norm(), 0.0);             // y_1 = z_1 = 0
    const int dim = m.SpatialDimension();
    EXPECT_EQ((nodes.col(p.Integer("n")).head(dim) - pt.u.head(dim)).norm(), 0.0);  // p_n is the grasp
    EXPECT_EQ(m.Probe(pt.x, pt.u), nodes(1, p.Integer("n") / 2));
    if (GraspLayoutOf(p).grip_direction) {
      // Node N-1 sits on the grip line at distance s behind p_N.
      const Eigen::Vector3d d = pt.u.tail<3>().normalized();
      const Eigen::Vector3d back = nodes.col(p.Integer("n")) - nodes.col(p.Integer("n") - 1);
      EXPECT_NEAR(back.dot(d), pt.x[m.NumStates() - 1], 1e-12);
      EXPECT_LE((back - back.dot(d) * d).norm(), 1e-12);
    }
    // The initial state spans the chord: evenly spaced along it, off it only by the
    // 1e-3 l symmetry-breaking bump.
    const Vec x0 = m.InitialState(pt.u);
    ASSERT_EQ(x0.size(), m.NumStates());
    Eigen::Matrix3Xd n0;
    m.NodePositions(x0, pt.u, &n0);
    const Eigen::Vector3d chord = n0.col(p.Integer("n"));
    for (int i = 1; i < p.Integer("n"); ++i) {
      if (GraspLayoutOf(p).grip_direction && i == p.Integer("n") - 1) continue;
      const Eigen::Vector3d expected = chord * (static_cast<double>(i) / p.Integer("n"));
      const double tol = 1e-3 * p.Number("segment_length") + 1e-12;
      if (i == 1) {
        EXPECT_LE(std::abs(n0(0, 1) - expected.x()), tol);  // its y, z are clamped to 0
      } else {
        EXPECT_LE((n0.col(i) - expected).norm(), tol) << "node " << i;
        EXPECT_GT((n0.col(i) - expected).norm(), 0.0) << "no symmetry-breaking bump at " << i;
      }
    }
  } else if (p.model == "rod") {
    ASSERT_EQ(nodes.cols(), p.Integer("n") + 1);
    // Clamped at 0 (or, without a clamp, held there by the first grasp u[0..5] = 0).
    EXPECT_EQ(nodes.col(0).norm(), 0.0);
    const Eigen::Vector3d held = pt.u.segment<3>(m.NumControls() - 6);
    EXPECT_EQ((nodes.col(p.Integer("n")) - held).norm(), 0.0);  // held at the grasp
    // Probe: the largest distance of a node from the clamp-grasp line.
    const Eigen::Vector3d d = held.normalized();
    double probe = 0.0;
    for (int k = 0; k < nodes.cols(); ++k) {
      probe = std::max(probe, (nodes.col(k) - nodes.col(k).dot(d) * d).norm());
    }
    EXPECT_NEAR(m.Probe(pt.x, pt.u), probe, 1e-12);
  } else if (p.model == "zeeman") {
    ASSERT_EQ(nodes.cols(), 4);
    EXPECT_NEAR(nodes.col(1).norm(), 1.0, 1e-15);               // wheel point on the unit wheel
    EXPECT_EQ(nodes.col(2), Eigen::Vector3d(0.0, -3.0, 0.0));   // anchor
    EXPECT_EQ(m.Probe(pt.x, pt.u), pt.x[0]);
  }
}

TEST(ModelFactoryTest, ConstructorsValidateParams) {
  ModelParams curve{.model = "curve2d"};
  ModelParams thread{.model = "thread3d"};
  curve.Set("n", 1);
  thread.Set("n", 1);
  EXPECT_THROW(MakeModel(curve), std::invalid_argument);
  EXPECT_THROW(MakeModel(thread), std::invalid_argument);
  thread.Set("n", 2);
  thread.Set("grip_direction", true);  // a grip needs N >= 3 (node N-1 must not be the clamped node 1)
  EXPECT_THROW(MakeModel(thread), std::invalid_argument);
  thread.Set("n", 3);
  EXPECT_EQ(MakeModel(thread)->NumStates(), 2);  // x_1 and s
  curve.Set("n", 3);
  curve.Set("stretching", -1.0);
  EXPECT_THROW(MakeModel(curve), std::invalid_argument);
  EXPECT_EQ(MakeModel({.model = "zeeman"})->Name(), "zeeman");
}

INSTANTIATE_TEST_SUITE_P(AllModels, ModelDerivativeTest, ::testing::ValuesIn(AllCases()),
                         [](const ::testing::TestParamInfo<Case>& info) { return info.param.name; });

}  // namespace
}  // namespace snapthread
