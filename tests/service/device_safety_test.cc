// Safety layer of snapthread-device: model preparation (reject / clamp stiffness),
// force clamp, slew limit, watchdog fade and recovery, bad poses, and a fuzz proving the
// output is always finite and bounded. Also the scripted path and the virtual hand.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include <Eigen/Eigenvalues>

#include "safety.h"
#include "scripted_path.h"
#include "sim_path_device.h"
#include "messages/pose_mapping.h"
#include "scene/scene.h"
#include "virtual_hand_device.h"

namespace snapthread::device {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr int64_t kTickUs = 1000;

force_model_t Model(double f0x, double stiffness_n_per_m) {
  force_model_t m{};
  m.seq = 1;
  m.status = force_model_t::STATUS_REGULAR;
  m.f0[0] = f0x;
  for (int i = 0; i < 3; ++i) m.K[i][i] = -stiffness_n_per_m;  // a spring: K = dF/du < 0
  return m;
}

// The limits the tests below are written for, spelled out so that a change of the
// defaults does not change the tests.
SafetyLimits TestLimits() {
  return {.max_force_n = 3.0, .max_stiffness_n_per_m = 800.0, .max_force_rate_n_per_s = 1000.0,
          .model_timeout_s = 0.050, .fade_time_s = 0.100, .workspace_radius_m = 0.08,
          .tick_period_s = 0.001};
}

LocalModel Prepared(const force_model_t& msg, int64_t receive_us,
                    const SafetyLimits& limits = TestLimits()) {
  LocalModel m;
  std::string why;
  EXPECT_NE(PrepareModel(msg, receive_us, limits, &m, &why), ModelVerdict::kRejected) << why;
  return m;
}

double Norm(const double f[3]) { return std::sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]); }


// The force safety layer with TestLimits() and the device at the origin, from t = 0.
class DeviceForceSafetyTest : public ::testing::Test {
 protected:
  // Runs ticks at 1 ms with *m kept fresh (received at every tick); 200 ticks complete
  // the fade-in.
  void Settle(LocalModel* m, int ticks = 200) {
    for (int i = 0; i < ticks; ++i) {
      m->receive_us = now_;
      safety_.Step(kOrigin, true, m, now_, &out_);
      now_ += kTickUs;
    }
  }
  // A ramp over the fade time, not a step: done within fade_time (+ 2 ticks), and not
  // before 90 % of it.
  void ExpectRampOverFadeTime(int ticks) const {
    ASSERT_GT(ticks, 0);
    EXPECT_LE(ticks, 1e3 * limits_.fade_time_s + 2);
    EXPECT_GE(ticks, 0.9e3 * limits_.fade_time_s);
  }

  static constexpr double kOrigin[3] = {0.0, 0.0, 0.0};
  const SafetyLimits limits_ = TestLimits();
  ForceSafety safety_{limits_, false};
  int64_t now_ = 0;
  SafetyOutput out_;
};

// ---- PrepareModel -----------------------------------------------------------------------

TEST(DevicePrepareModelTest, NonFiniteModelsAreRejected) {
  const SafetyLimits limits = TestLimits();
  int rejected = 0, total = 0;
  for (double bad : {kNaN, kInf, -kInf}) {
    for (int i = 0; i < 3; ++i) {
      force_model_t a = Model(1.0, 100.0); a.f0[i] = bad;
      force_model_t b = Model(1.0, 100.0); b.u0[i] = bad;
      force_model_t c = Model(1.0, 100.0); c.K[i][(i + 1) % 3] = bad;
      force_model_t d = Model(1.0, 100.0); d.has_torque = 1; d.torque0[i] = bad;
      for (const auto* m : {&a, &b, &c, &d}) {
        LocalModel out;
        out.seq = -77;
        std::string why;
        ++total;
        if (PrepareModel(*m, 0, limits, &out, &why) == ModelVerdict::kRejected) {
          ++rejected;
          EXPECT_FALSE(why.empty());
          EXPECT_EQ(out.seq, -77);  // untouched: never reaches the servo
        }
      }
    }
  }
  EXPECT_EQ(rejected, total);
  force_model_t s = Model(1.0, 100.0);
  s.status = 9;
  LocalModel out;
  EXPECT_EQ(PrepareModel(s, 0, limits, &out, nullptr), ModelVerdict::kRejected);
}

TEST(DevicePrepareModelTest, InvalidStatusBecomesZeroForce) {
  force_model_t m = Model(2.0, 300.0);
  m.status = force_model_t::STATUS_INVALID;
  LocalModel out;
  ASSERT_EQ(PrepareModel(m, 5, TestLimits(), &out, nullptr), ModelVerdict::kInvalidStatus);
  EXPECT_EQ(out.receive_us, 5);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(out.f0_n[i], 0.0);
    for (int j = 0; j < 3; ++j) EXPECT_EQ(out.K_n_per_m[i][j], 0.0);
  }
}

TEST(DevicePrepareModelTest, StableSpringPassesUnchanged) {
  force_model_t m = Model(0.5, 300.0);
  m.K[0][1] = m.K[1][0] = 20.0;
  LocalModel out;
  ASSERT_EQ(PrepareModel(m, 0, TestLimits(), &out, nullptr), ModelVerdict::kAccepted);
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) EXPECT_NEAR(out.K_n_per_m[i][j], m.K[i][j], 1e-9);
  }
  EXPECT_EQ(out.f0_n[0], 0.5);
}

// Eigenvalues of the stiffness S = -sym(K) of a prepared model.
Eigen::Vector3d Stiffnesses(const LocalModel& m) {
  Eigen::Matrix3d K;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) K(i, j) = m.K_n_per_m[i][j];
  }
  EXPECT_NEAR((K - K.transpose()).norm(), 0.0, 1e-9);
  return Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(-K).eigenvalues();
}

TEST(DevicePrepareModelTest, NegativeAndHugeStiffnessAreClamped) {
  // S has eigenvalues {-50, 200, 5000} in a rotated basis; K = -S plus an antisymmetric
  // part that symmetrisation must remove.
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Eigen::Matrix3d S = R * Eigen::Vector3d(-50, 200, 5000).asDiagonal() * R.transpose();
  Eigen::Matrix3d A;
  A << 0, 30, -10, -30, 0, 5, 10, -5, 0;
  const Eigen::Matrix3d K = -S + A;
  force_model_t m = Model(0.0, 0.0);
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) m.K[i][j] = K(i, j);
  }
  LocalModel out;
  ASSERT_EQ(PrepareModel(m, 0, TestLimits(), &out, nullptr), ModelVerdict::kStiffnessClamped);
  const Eigen::Vector3d s = Stiffnesses(out);
  EXPECT_NEAR(s[0], 0.0, 1e-6);
  EXPECT_NEAR(s[1], 200.0, 1e-6);
  EXPECT_NEAR(s[2], 800.0, 1e-6);

  // A purely negative stiffness (dF/du > 0: the force pushes the hand further away).
  LocalModel neg;
  ASSERT_EQ(PrepareModel(Model(0.0, -400.0), 0, TestLimits(), &neg, nullptr),
            ModelVerdict::kStiffnessClamped);
  EXPECT_NEAR(Stiffnesses(neg).cwiseAbs().maxCoeff(), 0.0, 1e-9);
}

TEST(DeviceLimitsTest, SmallerOfDeviceAndScene) {
  DeviceCapabilities caps;
  caps.max_force_n = 8.0;
  caps.max_stiffness_n_per_m = 500.0;
  caps.workspace_radius_m = 0.25;
  DeviceMapping mapping;
  mapping.max_force_n = 3.0;
  mapping.max_stiffness_n_per_m = 800.0;
  mapping.workspace_radius_m = 0.08;
  const SafetyLimits l = LimitsFrom(caps, &mapping);
  EXPECT_EQ(l.max_force_n, 3.0);
  EXPECT_EQ(l.max_stiffness_n_per_m, 500.0);
  EXPECT_EQ(l.workspace_radius_m, 0.08);
  const SafetyLimits d = LimitsFrom(caps, nullptr);
  EXPECT_EQ(d.max_force_n, 8.0);
  SafetyLimits bad = TestLimits();
  bad.fade_time_s = 0.0;
  EXPECT_FALSE(bad.IsValid(nullptr));
  EXPECT_THROW(ForceSafety(bad, false), std::invalid_argument);
}

// ---- ForceSafety ----------------------------------------------------------------------

TEST_F(DeviceForceSafetyTest, EvaluatesTheLocalModel) {
  ForceSafety s(TestLimits(), false);
  force_model_t msg = Model(0.2, 100.0);
  msg.u0[0] = 0.01;
  const double pos[3] = {0.02, -0.01, 0.0};
  int64_t now = 1000000;
  SafetyOutput out;
  for (int i = 0; i < 300; ++i) {  // fresh model every tick, past the fade-in
    const LocalModel m = Prepared(msg, now);
    s.Step(pos, true, &m, now, &out);
    now += kTickUs;
  }
  // F = f0 + K (u - u0) = (0.2 - 100*0.01, -100*(-0.01), 0)
  EXPECT_NEAR(out.force_n[0], -0.8, 1e-12);
  EXPECT_NEAR(out.force_n[1], 1.0, 1e-12);
  EXPECT_NEAR(out.force_n[2], 0.0, 1e-12);
  EXPECT_EQ(out.gain, 1.0);
  EXPECT_FALSE(out.fading);
}

TEST_F(DeviceForceSafetyTest, ForceMagnitudeIsClamped) {
  ForceSafety s(TestLimits(), false);
  force_model_t msg = Model(0.0, 0.0);
  msg.f0[0] = 30.0;
  msg.f0[1] = -40.0;  // |f0| = 50 N
  const double pos[3] = {0, 0, 0};
  int64_t now = 0;
  SafetyOutput out;
  const LocalModel m = Prepared(msg, now);
  for (int i = 0; i < 40; ++i) {
    s.Step(pos, true, &m, now, &out);
    EXPECT_LE(Norm(out.force_n), 3.0 + 1e-12);
    now += kTickUs;
  }
  EXPECT_NEAR(Norm(out.force_n), 3.0, 1e-9);
  EXPECT_NEAR(out.force_n[0] / out.force_n[1], -0.75, 1e-9);  // direction kept
  EXPECT_TRUE(out.clamped);
  EXPECT_GT(s.counters().force_clamps.load(), 0u);
}

TEST_F(DeviceForceSafetyTest, SlewLimitBoundsEveryTickAndStillReachesTheTarget) {
  LocalModel small = Prepared(Model(0.1, 0.0), now_);
  Settle(&small);
  ASSERT_NEAR(out_.force_n[0], 0.1, 1e-12);
  const uint64_t before = safety_.counters().slew_limits.load();
  // A snap: 0.1 N -> 2.9 N in one model update.
  const double max_step = limits_.max_force_rate_n_per_s * limits_.tick_period_s;
  double prev = out_.force_n[0];
  int ticks_to_target = -1;
  for (int i = 0; i < 20; ++i) {
    const LocalModel big = Prepared(Model(2.9, 0.0), now_);
    safety_.Step(kOrigin, true, &big, now_, &out_);
    now_ += kTickUs;
    EXPECT_LE(std::abs(out_.force_n[0] - prev), max_step + 1e-12);
    prev = out_.force_n[0];
    if (ticks_to_target < 0 && std::abs(out_.force_n[0] - 2.9) < 1e-12) ticks_to_target = i + 1;
  }
  EXPECT_EQ(ticks_to_target, 3);  // ceil(2.8 N / 1 N per tick): felt within 3 ms
  EXPECT_EQ(safety_.counters().slew_limits.load() - before, 2u);
}

TEST_F(DeviceForceSafetyTest, StaleModelFadesToZeroAndFreshModelRecovers) {
  LocalModel m = Prepared(Model(1.0, 0.0), now_);
  Settle(&m, 1);
  EXPECT_LT(out_.force_n[0], 0.05);  // fade-in from zero at start: gain ramps over fade_time
  Settle(&m, 240);
  ASSERT_NEAR(out_.force_n[0], 1.0, 1e-12);
  // The server goes silent: the model ages.
  const int64_t last_rx = m.receive_us;
  double prev = out_.force_n[0];
  int64_t zero_at_ms = -1;
  bool monotone = true;
  for (int i = 0; i < 400; ++i) {
    safety_.Step(kOrigin, true, &m, now_, &out_);
    const double age_ms = 1e-3 * static_cast<double>(now_ - last_rx);
    if (age_ms <= 1e3 * limits_.model_timeout_s) {
      EXPECT_NEAR(out_.force_n[0], 1.0, 1e-12) << age_ms;  // within the timeout: untouched
      EXPECT_FALSE(out_.fading);
    } else {
      EXPECT_TRUE(out_.fading);
    }
    if (out_.force_n[0] > prev + 1e-12) monotone = false;
    prev = out_.force_n[0];
    if (zero_at_ms < 0 && out_.force_n[0] == 0.0) zero_at_ms = static_cast<int64_t>(age_ms);
    now_ += kTickUs;
  }
  EXPECT_TRUE(monotone);
  ASSERT_GE(zero_at_ms, 0);
  // Zero no earlier than timeout + most of the fade (linear) and no later than timeout +
  // fade + one tick.
  EXPECT_GE(zero_at_ms, 1e3 * (limits_.model_timeout_s + 0.9 * limits_.fade_time_s));
  EXPECT_LE(zero_at_ms, 1e3 * (limits_.model_timeout_s + limits_.fade_time_s) + 2);
  EXPECT_EQ(out_.force_n[0], 0.0);
  EXPECT_GT(safety_.counters().fade_ticks.load(), 300u);
  // A fresh model: the force fades back in within the fade time.
  int recovered_after = -1;
  for (int i = 0; i < 300; ++i) {
    Settle(&m, 1);
    EXPECT_FALSE(out_.fading);
    if (recovered_after < 0 && std::abs(out_.force_n[0] - 1.0) < 1e-12) recovered_after = i + 1;
  }
  ExpectRampOverFadeTime(recovered_after);
}

// A stop (SIGINT/SIGTERM in snapthread-device) fades a fresh model's force to zero
// within the fade time, monotonically and within the slew limit, and it stays there.
TEST_F(DeviceForceSafetyTest, FadeOutOnStopReachesZeroWithinTheRamp) {
  LocalModel m = Prepared(Model(2.5, 0.0), now_);
  Settle(&m, 300);
  ASSERT_NEAR(out_.force_n[0], 2.5, 1e-12);
  safety_.RequestFadeOut();
  double prev = out_.force_n[0];
  int zero_after = -1;
  for (int i = 0; i < 300; ++i) {
    Settle(&m, 1);  // the model stays fresh: the stop alone fades the force
    EXPECT_TRUE(out_.fading);
    EXPECT_LE(out_.force_n[0], prev + 1e-12) << i;
    EXPECT_LE(prev - out_.force_n[0], limits_.max_force_rate_n_per_s * limits_.tick_period_s + 1e-9)
        << i;
    prev = out_.force_n[0];
    if (zero_after < 0 && out_.force_n[0] == 0.0) zero_after = i + 1;
  }
  ExpectRampOverFadeTime(zero_after);
  EXPECT_EQ(out_.force_n[0], 0.0);
}

TEST_F(DeviceForceSafetyTest, BadPosesFadeTheForceToZeroAtTheSlewLimit) {
  const SafetyLimits limits = TestLimits();
  const double step = limits.max_force_rate_n_per_s * limits.tick_period_s;
  ForceSafety s(limits, false);
  const double good[3] = {0.01, 0, 0};
  int64_t now = 0;
  SafetyOutput out;
  LocalModel m = Prepared(Model(1.5, 0.0), now);
  for (int i = 0; i < 300; ++i) {
    m.receive_us = now;
    s.Step(good, true, &m, now, &out);
    now += kTickUs;
  }
  ASSERT_NEAR(out.force_n[0], 1.5, 1e-12);
  ASSERT_LT(step, 1.5);  // so the fade takes more than one tick
  const double outside[3] = {0.0, 0.0, 0.081};
  const double nan_pose[3] = {0.0, kNaN, 0.0};
  const double inf_pose[3] = {kInf, 0.0, 0.0};
  const uint64_t before = s.counters().poses_rejected.load();
  double previous = 1.5;
  for (const double* p : {outside, nan_pose, inf_pose}) {
    m.receive_us = now;
    s.Step(p, true, &m, now, &out);
    now += kTickUs;
    EXPECT_TRUE(out.pose_rejected);
    // Toward zero, never up, never faster than the slew limit, never away from the last
    // direction.
    EXPECT_NEAR(Norm(out.force_n), std::max(previous - step, 0.0), 1e-12);
    EXPECT_GE(out.force_n[0], 0.0);
    EXPECT_EQ(out.force_n[1], 0.0);
    previous = Norm(out.force_n);
  }
  EXPECT_EQ(previous, 0.0);
  m.receive_us = now;
  s.Step(good, false, &m, now, &out);  // the device could not be read
  EXPECT_TRUE(out.pose_rejected);
  EXPECT_EQ(Norm(out.force_n), 0.0);
  EXPECT_EQ(s.counters().poses_rejected.load() - before, 4u);
  // Back in the workspace: the force comes back through the slew limit, not as a step.
  now += kTickUs;
  m.receive_us = now;
  s.Step(good, true, &m, now, &out);
  EXPECT_FALSE(out.pose_rejected);
  EXPECT_NEAR(out.force_n[0], step, 1e-12);
}

TEST_F(DeviceForceSafetyTest, FuzzOutputAlwaysFiniteAndBounded) {
  const SafetyLimits limits = TestLimits();
  ForceSafety s(limits, true, true);
  std::mt19937_64 rng(12345);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_int_distribution<int> pick(0, 9);
  std::uniform_int_distribution<int> percent(0, 99);
  auto wild = [&]() {
    const int r = percent(rng);
    if (r == 0) return kNaN;
    if (r == 1) return kInf;
    if (r == 2) return -kInf;
    if (r < 6) return 1e300 * unit(rng);
    if (r < 12) return 1e6 * unit(rng);
    return unit(rng);
  };
  int64_t now = 0;
  SafetyOutput out;
  LocalModel current;
  bool have = false;
  int accepted = 0;
  double prev[3] = {0, 0, 0};
  for (int i = 0; i < 100000; ++i) {
    if (pick(rng) < 3) {
      force_model_t msg{};
      msg.status = static_cast<int8_t>(pick(rng) % 5);
      msg.has_torque = static_cast<int8_t>(pick(rng) % 2);
      for (int a = 0; a < 3; ++a) {
        msg.u0[a] = 0.1 * wild();
        msg.f0[a] = 5.0 * wild();
        msg.torque0[a] = wild();
        for (int b = 0; b < 3; ++b) msg.K[a][b] = 2000.0 * wild();
      }
      LocalModel m;
      if (PrepareModel(msg, now, limits, &m, nullptr) != ModelVerdict::kRejected) {
        current = m;
        have = true;
        ++accepted;
      }
    }
    double pos[3];
    for (double& p : pos) p = pick(rng) == 0 ? wild() : 0.05 * unit(rng);
    // Irregular time steps, including stalls.
    now += pick(rng) == 0 ? 120000 : kTickUs;
    s.Step(pos, pick(rng) != 0, have ? &current : nullptr, now, &out);
    double step2 = 0.0;
    for (int k = 0; k < 3; ++k) {
      ASSERT_TRUE(std::isfinite(out.force_n[k])) << i;
      ASSERT_TRUE(std::isfinite(out.torque_nm[k])) << i;
      const double d = out.force_n[k] - prev[k];
      step2 += d * d;
      prev[k] = out.force_n[k];
    }
    ASSERT_LE(Norm(out.force_n), limits.max_force_n + 1e-9) << i;
    ASSERT_LE(Norm(out.torque_nm), limits.max_torque_nm + 1e-12) << i;
    if (!out.pose_rejected) {
      ASSERT_LE(std::sqrt(step2), limits.max_force_rate_n_per_s * limits.tick_period_s + 1e-9) << i;
    }
  }
  EXPECT_GT(accepted, 1000);
  EXPECT_GT(s.counters().force_clamps.load(), 0u);
  EXPECT_GT(s.counters().poses_rejected.load(), 0u);
  EXPECT_EQ(s.counters().nonfinite_outputs.load(), 0u);
  EXPECT_LE(s.max_force_n(), limits.max_force_n + 1e-9);
}

// ---- Scripted path and simulated devices ---------------------------------------------------

TEST(DeviceScriptedPathTest, BackAndForthAtConstantSpeed) {
  ScriptedPath p({{0.0, 0.0, 0.0}, {0.03, 0.0, 0.0}, {0.03, 0.01, 0.0}}, 0.02);
  EXPECT_NEAR(p.length_m(), 0.04, 1e-15);
  double x[3], v[3];
  p.Evaluate(0.5, x, v);  // 1 cm along the first leg
  EXPECT_NEAR(x[0], 0.01, 1e-12);
  EXPECT_NEAR(v[0], 0.02, 1e-12);
  p.Evaluate(1.75, x, v);  // 3.5 cm: half way up the second leg
  EXPECT_NEAR(x[0], 0.03, 1e-12);
  EXPECT_NEAR(x[1], 0.005, 1e-12);
  EXPECT_NEAR(v[1], 0.02, 1e-12);
  p.Evaluate(2.25, x, v);  // past the end (2 s): coming back, at 3.5 cm again
  EXPECT_NEAR(x[1], 0.005, 1e-12);
  EXPECT_NEAR(v[1], -0.02, 1e-12);
  p.Evaluate(4.0, x, v);  // back at the start
  EXPECT_NEAR(x[0], 0.0, 1e-12);
  EXPECT_THROW(ScriptedPath({}, 0.02), std::invalid_argument);
  EXPECT_THROW(ScriptedPath({{0, 0, 0}}, 0.0), std::invalid_argument);
}

TEST(DeviceScriptedPathTest, SceneWaypointsAreMappedToMetres) {
  const Scene scene = ParseScene(
      "model: zeeman\n"
      "grasp: {start: [0, 2.5], path: [[-2, 3.0], [2, 1.5]]}\n"
      "device: {model_units_per_metre: 100, model_origin: [0, 2.5, 0]}\n",
      "<test>");
  const ScriptedPath p = ScriptedPath::FromScene(scene, 0.02);
  ASSERT_EQ(p.waypoints_m().size(), 2u);
  EXPECT_NEAR(p.waypoints_m()[0][0], -0.02, 1e-15);
  EXPECT_NEAR(p.waypoints_m()[0][1], 0.005, 1e-15);
  EXPECT_NEAR(p.waypoints_m()[1][0], 0.02, 1e-15);
  EXPECT_NEAR(p.waypoints_m()[1][1], -0.01, 1e-15);
  // And back: model = origin + scale * device.
  const Eigen::Vector3d model =
      snapthread::messages::DeviceToModelPoint(scene.device, Eigen::Vector3d(-0.02, 0.005, 0.0));
  EXPECT_NEAR(model[0], -2.0, 1e-12);
  EXPECT_NEAR(model[1], 3.0, 1e-12);
}

int64_t g_fake_now_us = 0;
int64_t FakeClock() { return g_fake_now_us; }

TEST(DeviceSimDeviceTest, SimPathFollowsThePathAndIgnoresForce) {
  g_fake_now_us = 5000000;
  SimPathDevice d(ScriptedPath({{0, 0, 0}, {0.04, 0, 0}}, 0.02), &FakeClock);
  ASSERT_TRUE(d.Open(nullptr));
  DeviceState st;
  ASSERT_TRUE(d.Read(&st));
  EXPECT_EQ(st.position_m[0], 0.0);
  const double f[3] = {100, 0, 0}, t[3] = {0, 0, 0};
  ASSERT_TRUE(d.Command(f, t));
  g_fake_now_us += 1000000;
  ASSERT_TRUE(d.Read(&st));
  EXPECT_NEAR(st.position_m[0], 0.02, 1e-12);
  d.Close();
  EXPECT_FALSE(d.Read(&st));
}

// Closed haptic loop: virtual hand + safety + a local spring model evaluated each tick.
struct LoopResult {
  double max_speed_m_per_s = 0.0;  // over the second half
  double max_deviation_m = 0.0;    // hand from the scripted target, second half
};

LoopResult RunClosedLoop(double model_stiffness_n_per_m, bool prepare_model) {
  g_fake_now_us = 0;
  const ScriptedPath path({{0.0, 0.0, 0.0}, {0.02, 0.0, 0.0}}, 0.02);
  VirtualHandDevice hand(path, {}, &FakeClock);
  EXPECT_TRUE(hand.Open(nullptr));
  const SafetyLimits limits = TestLimits();
  ForceSafety s(limits, false);
  force_model_t msg = Model(0.0, model_stiffness_n_per_m);
  msg.u0[0] = 0.01;  // spring anchored mid-path
  LocalModel m;
  if (prepare_model) {
    m = Prepared(msg, 0);
  } else {
    // What the servo would render without the stiffness clamp.
    m.status = force_model_t::STATUS_REGULAR;
    m.u0_m[0] = 0.01;
    for (int i = 0; i < 3; ++i) m.K_n_per_m[i][i] = -model_stiffness_n_per_m;
  }
  DeviceState st;
  SafetyOutput out;
  LoopResult r;
  for (int i = 0; i < 2000; ++i) {
    g_fake_now_us += kTickUs;
    hand.Read(&st);
    m.receive_us = g_fake_now_us;
    s.Step(st.position_m, true, &m, g_fake_now_us, &out);
    hand.Command(out.force_n, out.torque_nm);
    if (i > 1000) {
      double target[3], v[3];
      path.Evaluate(1e-6 * static_cast<double>(g_fake_now_us - kTickUs), target, v);
      double d2 = 0.0;
      for (int k = 0; k < 3; ++k) d2 += (st.position_m[k] - target[k]) * (st.position_m[k] - target[k]);
      r.max_deviation_m = std::max(r.max_deviation_m, std::sqrt(d2));
      r.max_speed_m_per_s = std::max(r.max_speed_m_per_s, Norm(st.velocity_m_per_s));
    }
  }
  return r;
}

TEST(DeviceVirtualHandTest, StiffSpringIsStableAndNegativeStiffnessIsTamed) {
  // A stable spring at the clamp limit: the hand moves smoothly (path speed 2 cm/s) and
  // stays within a spring-balance distance of its target (k_hand/(k_hand+k) of 1 cm).
  const LoopResult stable = RunClosedLoop(800.0, true);
  EXPECT_LT(stable.max_speed_m_per_s, 0.1);
  EXPECT_LT(stable.max_deviation_m, 0.011);
  // A negative stiffness of 5000 N/m would push the hand away until the force clamp
  // holds it (3 N / 200 N/m = 15 mm off its path); clamped to zero stiffness it cannot.
  const LoopResult raw = RunClosedLoop(-5000.0, false);
  EXPECT_GT(raw.max_deviation_m, 0.010);
  const LoopResult tamed = RunClosedLoop(-5000.0, true);
  EXPECT_LT(tamed.max_deviation_m, 0.002);
  EXPECT_LT(tamed.max_speed_m_per_s, 0.1);
}

TEST(DeviceVirtualHandTest, FollowsThePathWithoutForce) {
  g_fake_now_us = 0;
  VirtualHandDevice hand(ScriptedPath({{0.0, 0.0, 0.0}, {0.02, 0.0, 0.0}}, 0.01), {}, &FakeClock);
  ASSERT_TRUE(hand.Open(nullptr));
  DeviceState st;
  const double zero[3] = {0, 0, 0};
  for (int i = 0; i < 1000; ++i) {
    g_fake_now_us += kTickUs;
    hand.Read(&st);
    hand.Command(zero, zero);
  }
  // After 1 s at 1 cm/s the target is at 1 cm; a critically damped hand lags by about
  // 2 v / w = 2 * 0.01 / 44.7 = 0.45 mm.
  EXPECT_NEAR(st.position_m[0], 0.01, 0.001);
  EXPECT_LT(st.position_m[0], 0.01);
  // A constant push of 1 N moves it by F / k = 5 mm.
  const double push[3] = {0, 1.0, 0};
  for (int i = 0; i < 1000; ++i) {
    g_fake_now_us += kTickUs;
    hand.Read(&st);
    hand.Command(push, zero);
  }
  EXPECT_NEAR(st.position_m[1], 1.0 / 200.0, 2e-4);
}

}  // namespace
}  // namespace snapthread::device
