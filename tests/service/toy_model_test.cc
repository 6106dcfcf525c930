// A model added the way docs/adding-a-model.md says, but at run time and only here: a
// bead on a hardening spring pulled by the grasp,
//   E(x, u) = k/2 (x - X)^2 + c/4 x^4,   u = (X, Y) (Y is free: nothing pulls on it).
// Registered once, it loads from a scene, runs through the sweep and through an
// in-process server over an in-memory transport (server_memory_transport.h), and both
// find the equilibrium k (x - X) + c x^3 = 0 with the force F = -E_u = (k (x - X), 0).
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <unistd.h>

#include "auth/message_mac.h"
#include "auth/session_epoch.h"
#include "messages/pose_mapping.h"
#include "session_key_file.h"
#include "models/models.h"
#include "scene/scene.h"
#include "server.h"
#include "server_memory_transport.h"
#include "sweep.h"
#include "tracking/make_tracker.h"

namespace snapthread {
namespace {

using namespace std::chrono_literals;

constexpr char kToy[] = "toy_spring";

class SpringModel final : public Model {
 public:
  explicit SpringModel(const ModelParams& p) : k_(p.Number("k")), c_(p.Number("c")) {
    pattern_.resize(1, 1);
    pattern_.insert(0, 0) = 0.0;
    pattern_.makeCompressed();
  }
  std::string_view Name() const override { return kToy; }
  int NumStates() const override { return 1; }
  int NumControls() const override { return 2; }
  int SpatialDimension() const override { return 2; }
  double Energy(const Vec& x, const Vec& u) const override {
    const double d = x[0] - u[0];
    return 0.5 * k_ * d * d + 0.25 * c_ * std::pow(x[0], 4);
  }
  void Gradient(const Vec& x, const Vec& u, Vec* g) const override {
    if (g->size() != 1) g->resize(1);
    (*g)[0] = k_ * (x[0] - u[0]) + c_ * x[0] * x[0] * x[0];
  }
  const SparseMatrix& HessianPattern() const override { return pattern_; }
  void Hessian(const Vec& x, const Vec&, SparseMatrix* h) const override {
    if (h->rows() != 1 || h->nonZeros() != 1) *h = pattern_;
    h->valuePtr()[0] = k_ + 3.0 * c_ * x[0] * x[0];
  }
  void ControlGradient(const Vec& x, const Vec& u, Vec* eu) const override {
    if (eu->size() != 2) eu->resize(2);
    (*eu)[0] = -k_ * (x[0] - u[0]);
    (*eu)[1] = 0.0;
  }
  void MixedHessian(const Vec&, const Vec&, Mat* exu) const override {
    if (exu->rows() != 1 || exu->cols() != 2) exu->resize(1, 2);
    (*exu)(0, 0) = -k_;
    (*exu)(0, 1) = 0.0;
  }
  void ControlHessian(const Vec&, const Vec&, Mat* euu) const override {
    if (euu->rows() != 2 || euu->cols() != 2) euu->resize(2, 2);
    euu->setZero();
    (*euu)(0, 0) = k_;
  }
  Vec InitialState(const Vec& u) const override { return Vec::Constant(1, u[0]); }
  void NodePositions(const Vec& x, const Vec& u, Eigen::Matrix3Xd* nodes) const override {
    if (nodes->cols() != 2) nodes->resize(3, 2);
    nodes->col(0) << x[0], 0.0, 0.0;  // the bead
    nodes->col(1) << u[0], u[1], 0.0;  // the grasp
  }
  double Probe(const Vec& x, const Vec&) const override { return x[0]; }
  double ForceScale() const override { return k_; }
  int HessianBandwidth() const override { return 0; }

 private:
  double k_, c_;
  SparseMatrix pattern_;
};

// The one registration (at run time, once per process).
void RegisterToy() {
  if (FindModel(kToy) != nullptr) return;
  ModelRegistration r;
  r.name = kToy;
  r.doc = "test only: a bead on a hardening spring, E = k/2 (x - X)^2 + c/4 x^4";
  r.params = {
      {.name = "k", .default_value = 2.0, .min = 0.0, .min_inclusive = false, .units = "force / length",
       .doc = "linear stiffness"},
      {.name = "c", .default_value = 1.0, .min = 0.0, .units = "force / length^3", .doc = "cubic hardening"},
  };
  r.factory = [](const ModelParams& p) -> std::unique_ptr<Model> { return std::make_unique<SpringModel>(p); };
  r.capabilities.grasp_layout = [](const ModelParams&) { return GraspLayout{.spatial_dimension = 2}; };
  RegisterModel(std::move(r));
}

constexpr double kK = 3.0, kC = 0.5;

const char* kSceneText = R"(
name: toy_spring
model: toy_spring
params: {k: 3.0, c: 0.5}
grasp:
  start: [-2.0, 0.0]
  path: [[-2.0, 0.0], [2.0, 0.5]]
solver: {method: newton, cutoff: 1.0e-10}
device:
  model_units_per_metre: 50.0
  model_origin: [0.0, 0.0, 0.0]
)";

// The equilibrium k (x - X) + c x^3 = 0 by bisection (it is unique: E is convex in x).
double Equilibrium(double big_x) {
  double lo = -std::abs(big_x) - 1.0, hi = std::abs(big_x) + 1.0;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (kK * (mid - big_x) + kC * mid * mid * mid > 0.0 ? hi : lo) = mid;
  }
  return 0.5 * (lo + hi);
}

void ExpectEquilibrium(const Vec& u, const Vec& x, const Vec& force, const std::string& where) {
  ASSERT_EQ(x.size(), 1) << where;
  ASSERT_EQ(force.size(), 2) << where;
  EXPECT_NEAR(x[0], Equilibrium(u[0]), 1e-9) << where;
  EXPECT_LE(std::abs(kK * (x[0] - u[0]) + kC * std::pow(x[0], 3)), 1e-9) << where;  // E_x = 0
  EXPECT_NEAR(force[0], kK * (x[0] - u[0]), 1e-12) << where;                         // F = -E_u
  EXPECT_EQ(force[1], 0.0) << where;
}

TEST(ToyModel, RegistryListsItAndTheSceneSchemaChecksIt) {
  RegisterToy();
  EXPECT_NE(ModelNameList().find(kToy), std::string::npos);
  EXPECT_NE(ModelHelp().find("params.k (a number > 0"), std::string::npos) << ModelHelp();
  EXPECT_THROW(RegisterModel(*FindModel(kToy)), std::invalid_argument);  // a name is taken once
  const Scene s = ParseScene(kSceneText, "toy.yaml");
  EXPECT_EQ(s.params.Number("k"), kK);
  EXPECT_EQ(SnapLengthScale(s.params), 1.0);
  EXPECT_FALSE(IsChain(s.params));
  try {
    ParseScene("model: toy_spring\nparams: {k: -1}\ngrasp: {start: [0, 0]}", "toy.yaml");
    FAIL();
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("toy.yaml: params.k: expected a number > 0, got -1"), std::string::npos)
        << e.what();
  }
  try {
    ParseScene("model: toy_spring\nparams: {n: 3}\ngrasp: {start: [0, 0]}", "toy.yaml");
    FAIL();
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("params.n: unknown key (expected one of: c, k)"), std::string::npos)
        << e.what();
  }
}

TEST(ToyModel, SweepReachesTheEquilibriumWithForceMinusEu) {
  RegisterToy();
  const Scene scene = ParseScene(kSceneText, "toy.yaml");
  auto tracker = MakeTracker(scene);
  const std::vector<SweepRow> rows = RunSweep(tracker.get(), PathControls(scene, 40));
  ASSERT_EQ(rows.size(), 41u);
  for (const SweepRow& r : rows) {
    ExpectEquilibrium(r.u, r.state, r.force, "sweep row " + std::to_string(r.step));
    EXPECT_LE(r.residual, 1e-10);
    EXPECT_FALSE(r.snapped);  // one convex well: nothing to snap to
  }
  // The hardening spring holds the bead back: |x| < |X| away from 0.
  EXPECT_LT(std::abs(rows.back().state[0]), 2.0);
}

// The server loads the scene from a file, answers poses, and its tracker sits on the
// same equilibria with the same forces.
TEST(ToyModel, InProcessServerAnswersWithTheEquilibriumForce) {
  RegisterToy();
  const std::filesystem::path file =
      std::filesystem::temp_directory_path() / ("snapthread_toy_" + std::to_string(::getpid()) + ".yaml");
  std::ofstream(file) << kSceneText;
  const Scene scene = LoadScene(file.string());

  struct Row {
    Vec u, x, force;
  };
  std::mutex mutex;
  std::condition_variable cv;
  std::vector<Row> rows;
  server::testing::MemoryServerTransport transport;
  const test_support::SessionKeyFile key_file;  // the server's root key
  const auth::KeySet hand = server::testing::DeviceKeys(key_file.key());  // poses are the device "hand"'s
  auth::AuthSequence auth_seq;
  server::ServerParams params;
  params.key_path = key_file.path();
  params.session = "TOY";
  params.scene_path = file.string();
  params.log_level = "warn";
  server::ServerTestHooks hooks;
  hooks.after_update = [&](const Vec& u, const EquilibriumTracker& t) {
    std::lock_guard<std::mutex> lock(mutex);
    rows.push_back({u, t.state(), t.last().force});
    cv.notify_all();
  };
  server::Server srv(params, &transport, std::move(hooks));
  srv.Start();
  const std::vector<Vec> path = PathControls(scene, 20);
  for (size_t i = 1; i < path.size(); ++i) {
    device_state_t s{};
    s.utime = 1000 + static_cast<int64_t>(i);
    s.seq = static_cast<int64_t>(i);
    s.device_id = "test";
    const Eigen::Vector3d p = messages::ControlsToPosition(scene.device, scene.grasp_layout, path[i]);
    for (int a = 0; a < 3; ++a) s.position[a] = p[a];
    s.orientation[0] = 1.0;
    s.buttons = 1;
    ASSERT_TRUE(auth::Sign(&s, srv.channels().device_state, srv.epoch(), auth_seq.Next(), hand.tagger()));
    transport.DeliverDeviceState(test_support::Encode(s));
    std::unique_lock<std::mutex> lock(mutex);
    ASSERT_TRUE(cv.wait_for(lock, 20s, [&] { return rows.size() >= i; })) << "no update for pose " << i;
  }
  srv.Stop();
  std::filesystem::remove(file);
  ASSERT_EQ(rows.size(), path.size() - 1);
  for (size_t i = 0; i < rows.size(); ++i) {
    EXPECT_NEAR(rows[i].u[0], path[i + 1][0], 1e-12);
    ExpectEquilibrium(rows[i].u, rows[i].x, rows[i].force, "server update " + std::to_string(i));
  }
  EXPECT_EQ(srv.Stats().updates, static_cast<int64_t>(rows.size()));
  EXPECT_EQ(srv.Stats().invalid_models, 0);
}

}  // namespace
}  // namespace snapthread
