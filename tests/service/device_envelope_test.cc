// Issue 12 item 10: the safety envelope holds under every hostile or lossy model stream
// this test can make in-process. A DeviceClient runs on a fake clock for 24,000 ticks
// through a lossy, reordering link (lossy_transport.h) to a server fake that, phase by
// phase, sends NaN and inf fields, huge forces and stiffnesses, K neither symmetric nor
// stable, models of a stale server session, bursts, nothing at all, 10 N jumps, models
// expanded about absurd poses, INVALID models and garbage. Every tick the force handed to
// the device backend must be finite, within the configured limit, and within 1 N of the
// previous tick's (the safety layer's clamps and slew limit, device_client/safety.h). The
// path stays inside the workspace: a pose the device cannot trust is released at once by
// design (ForceSafety::Step), which is not a model stream.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "auth/session_epoch.h"
#include "auth/session_key.h"
#include "device_client.h"
#include "device_fakes.h"
#include "lossy_transport.h"
#include "safety.h"
#include "sim_path_device.h"

namespace snapthread::device {
namespace {

// The fake clock every step of the run reads.
int64_t g_now_us = 0;
int64_t FakeClock() { return g_now_us; }
using testing::InMemoryTransport;
using testing::SpringServer;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kMax = std::numeric_limits<double>::max();

// The streams, one per phase of kPhaseTicks ticks, in a seeded random order.
enum class Stream {
  kSpring,          // a genuine 300 N/m spring (asks for more than the limit: clamps)
  kNonFinite,       // one NaN or inf field in every model
  kHugeForce,       // f0 up to the largest double
  kHugeStiffness,   // K entries up to the largest double, not symmetric
  kWildStiffness,   // K neither symmetric nor stable (energy-releasing), ±10^4 N/m
  kStaleEpoch,      // signed by the key, but for another server session
  kBursts,          // nothing for 25 ms, then 25 models at once, ±3 N alternating
  kSilence,         // no models at all (the watchdog fades)
  kJump10N,         // every model 10 N away from the previous one
  kFarExpansion,    // u0 far from the pose: f0 + K (u - u0) overflows
  kInvalidStatus,   // INVALID models between strong ones
  kGarbage,         // random bytes, truncated models, log-uniform random fields
  kCount,
};
constexpr int kStreams = static_cast<int>(Stream::kCount);
constexpr int kPhaseTicks = 250;
constexpr int kRounds = 8;  // every stream 8 times: 24,000 ticks

class HostileServer {
 public:
  HostileServer(InMemoryTransport* wire, const auth::SessionKey* key, const std::string& session,
                uint32_t seed)
      : wire_(wire), spring_(wire, 300.0), stale_(wire, 300.0), rng_(seed) {
    if (key != nullptr) {
      spring_.SignWith(key, auth::NewEpoch(), session);
      stale_.SignWith(key, auth::NewEpoch(), session);  // another session's epoch
    }
  }

  void Status() { spring_.DeliverStatus(); }

  // Answers the poses that reached the server during this tick, as `stream` does.
  void Answer(Stream stream, int tick) {
    for (const device_state_t& pose : spring_.TakeNewPoses()) {
      force_model_t m = spring_.ModelFor(pose);
      switch (stream) {
        case Stream::kSpring: break;
        case Stream::kNonFinite: Field(&m) = Pick({kNaN, kInf, -kInf}); break;
        case Stream::kHugeForce:
          for (double& f : m.f0) f = Pick({1e6, -1e6, 1e300, -1e300, kMax, -kMax});
          break;
        case Stream::kHugeStiffness:
          for (auto& row : m.K) {
            for (double& k : row) k = Pick({1e9, -1e9, 1e300, -1e300, kMax, -kMax, 0.0});
          }
          break;
        case Stream::kWildStiffness:
          for (auto& row : m.K) {
            for (double& k : row) k = Uniform(-1e4, 1e4);
          }
          break;
        case Stream::kStaleEpoch: stale_.Send(m); continue;
        case Stream::kBursts:
          m.f0[0] = held_.size() % 2 == 0 ? 3.0 : -3.0;
          held_.push_back(m);
          if (tick % 25 == 0) {
            std::shuffle(held_.begin(), held_.end(), rng_);
            for (const force_model_t& h : held_) spring_.Send(h);
            held_.clear();
          }
          continue;
        case Stream::kSilence: continue;
        case Stream::kJump10N:
          jump_sign_ = -jump_sign_;
          for (auto& row : m.K) {
            for (double& k : row) k = 0.0;
          }
          m.f0[0] = 5.0 * jump_sign_;
          m.f0[1] = m.f0[2] = 0.0;
          break;
        case Stream::kFarExpansion:
          for (double& u : m.u0) u = Pick({1e3, -1e3, 1e300, -1e300, kMax});
          break;
        case Stream::kInvalidStatus:
          m.status = Uniform(0.0, 1.0) < 0.5 ? force_model_t::STATUS_INVALID
                                             : force_model_t::STATUS_SNAPPED;
          m.f0[1] = 3.0;
          break;
        case Stream::kGarbage: SendGarbage(m); continue;
        case Stream::kCount: break;
      }
      spring_.Send(m);
    }
  }

 private:
  double Uniform(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng_); }
  double Pick(std::initializer_list<double> values) {
    std::uniform_int_distribution<size_t> i(0, values.size() - 1);
    return values.begin()[i(rng_)];
  }
  // Any double of a model, at random.
  double& Field(force_model_t* m) {
    const int k = std::uniform_int_distribution<int>(0, 18)(rng_);
    if (k < 3) return m->f0[k];
    if (k < 6) return m->u0[k - 3];
    if (k < 15) return m->K[(k - 6) / 3][(k - 6) % 3];
    if (k < 18) return m->torque0[k - 15];
    return m->residual;
  }
  // Random bytes, a truncated model, or every double log-uniform in ±[1e-300, 1e300].
  void SendGarbage(force_model_t m) {
    const double r = Uniform(0.0, 1.0);
    if (r < 0.2) {
      std::vector<uint8_t> bytes(static_cast<size_t>(Uniform(1.0, 400.0)));
      for (uint8_t& b : bytes) b = static_cast<uint8_t>(rng_());
      wire_->Deliver(std::move(bytes));
    } else if (r < 0.4) {
      std::vector<uint8_t> bytes = testing::Encoded(m);
      bytes.resize(static_cast<size_t>(Uniform(0.0, static_cast<double>(bytes.size()))));
      wire_->Deliver(std::move(bytes));
    } else {
      for (int k = 0; k < 19; ++k) {
        const double magnitude = std::pow(10.0, Uniform(-300.0, 300.0));
        Field(&m) = Uniform(0.0, 1.0) < 0.5 ? -magnitude : magnitude;
      }
      m.has_torque = static_cast<int8_t>(rng_() % 2);
      spring_.Send(m);
    }
  }

  InMemoryTransport* wire_;
  SpringServer spring_;
  SpringServer stale_;
  std::mt19937 rng_;
  std::vector<force_model_t> held_;
  double jump_sign_ = 1.0;
};

double Norm(const double v[3]) { return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

void RunHostileStreams(bool signed_session, uint32_t seed) {
  g_now_us = 1000000;
  // Inside the 8 cm workspace all along.
  SimPathDevice device(ScriptedPath({{-0.03, -0.01, 0.0}, {0.03, 0.02, 0.01}}, 0.05), &FakeClock);
  ASSERT_TRUE(device.Open(nullptr));
  InMemoryTransport wire;
  testing::LinkOptions link;  // 20 % loss, 5 ± 2 ms
  link.seed = seed;
  testing::LossyTransport lossy(&wire, link, &FakeClock);
  const auth::SessionKey key = auth::SessionKey::Generate();
  const std::unique_ptr<DeviceKeys> keys = testing::DeviceKeysFor(key);
  DeviceClientConfig config;
  config.device_id = "envelope-test";
  config.limits.max_force_n = 2.5;  // the configured limit, not the default
  config.loop.realtime = false;
  config.log_period_us = 0;
  config.clock = &FakeClock;
  if (signed_session) config.keys = keys.get();
  HostileServer server(&wire, signed_session ? &key : nullptr, config.session, seed);
  DeviceClient client(&device, &lossy, config);
  const SafetyLimits& limits = client.safety().limits();
  const double max_step_n = limits.max_force_rate_n_per_s * limits.tick_period_s;
  ASSERT_DOUBLE_EQ(max_step_n, 1.0);

  std::mt19937 order(seed);
  std::vector<Stream> phases;
  for (int round = 0; round < kRounds; ++round) {
    std::vector<Stream> all;
    for (int s = 0; s < kStreams; ++s) all.push_back(static_cast<Stream>(s));
    std::shuffle(all.begin(), all.end(), order);
    phases.insert(phases.end(), all.begin(), all.end());
  }

  double previous[3] = {0.0, 0.0, 0.0};
  double largest_n = 0.0, largest_step_n = 0.0;
  int broken = 0;
  const int ticks = static_cast<int>(phases.size()) * kPhaseTicks;
  for (int i = 0; i < ticks; ++i) {
    const Stream stream = phases[static_cast<size_t>(i / kPhaseTicks)];
    g_now_us += 1000;
    client.Tick(g_now_us, 0);
    const double* f = device.last_force_n();
    const double step[3] = {f[0] - previous[0], f[1] - previous[1], f[2] - previous[2]};
    const bool finite = std::isfinite(f[0]) && std::isfinite(f[1]) && std::isfinite(f[2]);
    const bool ok = finite && Norm(f) <= limits.max_force_n + 1e-12 &&
                    Norm(step) <= max_step_n + 1e-12;
    if (!ok && ++broken <= 5) {
      ADD_FAILURE() << "tick " << i << " stream " << static_cast<int>(stream) << ": F = (" << f[0]
                    << ", " << f[1] << ", " << f[2] << "), |dF| = " << Norm(step);
    }
    if (finite) {
      largest_n = std::max(largest_n, Norm(f));
      largest_step_n = std::max(largest_step_n, Norm(step));
    }
    for (int k = 0; k < 3; ++k) previous[k] = f[k];

    client.Service(g_now_us);
    if (i % 20 == 0) server.Status();
    server.Answer(stream, i);
    client.Receive(0);
  }
  EXPECT_EQ(broken, 0);
  // The streams did push on the envelope: the limits acted, and were reached.
  const DeviceClientSummary s = client.Summary(g_now_us);
  EXPECT_GT(largest_n, 0.99 * limits.max_force_n);
  EXPECT_GT(largest_step_n, 0.99 * max_step_n);
  EXPECT_GT(s.force_clamps, 1000u);
  EXPECT_GT(s.slew_limits, 1000u);
  EXPECT_GT(s.stiffness_clamps, 1000u);
  EXPECT_GT(s.fade_ticks, 500u);
  EXPECT_GT(s.models_rejected, 5000u);
  EXPECT_GT(s.models_received, 5000u);
  EXPECT_EQ(s.nonfinite_outputs, 0u);
  EXPECT_EQ(s.poses_rejected, 0u);
}

// A K whose entries are finite but whose symmetric part overflows (K + K^T) has no
// usable stiffness: it is refused, never handed to the servo with NaN or inf in it.
TEST(DeviceSafetyEnvelopeTest, StiffnessThatOverflowsIsRefused) {
  const double cases[][4] = {{kMax, kMax, 0.0, 0.0}, {kMax, -kMax, 0.0, 0.0},
                             {-kMax, -kMax, -kMax, -kMax}, {kMax, 0.0, 0.0, kMax},
                             {1e300, 1e300, 1e300, 1e300}};
  for (const auto& c : cases) {
    force_model_t m{};
    m.status = force_model_t::STATUS_REGULAR;
    m.K[0][1] = c[0];
    m.K[1][0] = c[1];
    m.K[0][0] = c[2];
    m.K[1][1] = c[3];
    LocalModel out;
    std::string why;
    const ModelVerdict v = PrepareModel(m, 0, SafetyLimits{}, &out, &why);
    if (v == ModelVerdict::kRejected) {
      EXPECT_FALSE(why.empty());
      continue;
    }
    for (const auto& row : out.K_n_per_m) {
      for (double k : row) EXPECT_TRUE(std::isfinite(k)) << c[0] << " " << c[1] << " " << c[2];
    }
  }
}

TEST(DeviceSafetyEnvelopeTest, HostileStreamsOverALossyLinkUnsigned) {
  for (uint32_t seed : {1u, 2u}) RunHostileStreams(false, seed);
}

TEST(DeviceSafetyEnvelopeTest, HostileStreamsOverALossyLinkSigned) {
  for (uint32_t seed : {3u, 4u}) RunHostileStreams(true, seed);
}

}  // namespace
}  // namespace snapthread::device
