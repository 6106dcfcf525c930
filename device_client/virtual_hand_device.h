// virtual-hand backend: a simulated hand holding the grasp. A point mass pulled toward
// the scripted path by a spring with near-critical damping and pushed by the rendered
// force: it closes the haptic loop, so a force model that would be unstable on a real
// device (negative stiffness, too stiff for the tick) shows up as oscillation here.
// The hand's orientation is the path's (a rod scene's roll), without dynamics: it senses
// orientation but renders no torque. The force pushes the hand only while the command is
// fresh (StaleCommand: zero once it is older than 5 ms, as a real backend's watchdog
// does), so a stalled servo thread leaves the hand unpushed, not pushed by its last
// force (the StaleCommand and render thread of simulated_device.h).
#pragma once

#include <cstdint>

#include "simulated_device.h"

namespace snapthread::device {

struct VirtualHandParams {
  double mass_kg = 0.1;                // hand + device effective mass
  double spring_n_per_m = 200.0;       // the arm's pull toward the intended path
  double damping_ratio = 1.0;          // of the hand alone (1 = critical)
  double max_substep_s = 0.0005;       // integration step bound (semi-implicit Euler)
  double max_dt_s = 0.05;              // longer gaps (stalls) are integrated as this long
};

class VirtualHandDevice final : public SimulatedDevice {
 public:
  VirtualHandDevice(ScriptedPath path, VirtualHandParams params, MicrosClock clock);

  bool Open(std::string* error) override;
  // Advances the hand by the time since the previous Read under the last commanded
  // force, then reports it.
  bool Read(DeviceState* state) override;
  bool Command(const double force_n[3], const double torque_nm[3]) override;
  void Close() override;

  // Steps the hand from t_s - dt_s to t_s (seconds since the first Read) under the force
  // rendered at each substep (also used by Read); public for tests.
  void Integrate(double t_s, double dt_s);
  const double* position_m() const { return x_; }

 private:
  VirtualHandParams params_;
  int64_t last_us_ = -1;
  double x_[3] = {0.0, 0.0, 0.0};
  double v_[3] = {0.0, 0.0, 0.0};
};

}  // namespace snapthread::device
