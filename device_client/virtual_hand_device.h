// virtual-hand backend: a simulated hand holding the grasp. A point mass pulled toward
// the scripted path by a spring with near-critical damping and pushed by the rendered
// force: it closes the haptic loop, so a force model that would be unstable on a real
// device (negative stiffness, too stiff for the tick) shows up as oscillation here.
// The hand's orientation is the path's (a rod scene's roll), without dynamics: it senses
// orientation but renders no torque. The force pushes the hand only while the command is
// fresh (StaleCommand: zero once it is older than 5 ms, as a real backend's watchdog
// does), so a stalled servo thread leaves the hand unpushed, not pushed by its last
// force; StartRenderer runs its "firmware" thread, which publishes the rendered output.
#pragma once

#include <cstdint>

#include "haptic_device.h"
#include "scripted_path.h"
#include "sim_clock.h"
#include "sim_renderer.h"
#include "stale_command.h"

namespace snapthread::device {

struct VirtualHandParams {
  double mass_kg = 0.1;                // hand + device effective mass
  double spring_n_per_m = 200.0;       // the arm's pull toward the intended path
  double damping_ratio = 1.0;          // of the hand alone (1 = critical)
  double max_substep_s = 0.0005;       // integration step bound (semi-implicit Euler)
  double max_dt_s = 0.05;              // longer gaps (stalls) are integrated as this long
};

class VirtualHandDevice final : public HapticDevice {
 public:
  VirtualHandDevice(ScriptedPath path, VirtualHandParams params, MicrosClock clock);

  bool Open(std::string* error) override;
  const DeviceCapabilities& capabilities() const override { return caps_; }
  // Advances the hand by the time since the previous Read under the last commanded
  // force, then reports it.
  bool Read(DeviceState* state) override;
  bool Command(const double force_n[3], const double torque_nm[3]) override;
  void Close() override;

  // Steps the hand from t_s - dt_s to t_s (seconds since the first Read) under the force
  // rendered at each substep (also used by Read); public for tests.
  void Integrate(double t_s, double dt_s);
  const double* position_m() const { return x_; }
  const StaleCommand& command() const { return command_; }
  // Starts the render thread ("" = record in memory only); see SimRenderer::Start.
  bool StartRenderer(const std::string& shared_file, std::string* error) {
    return renderer_.Start(shared_file, error);
  }
  const SimRenderer& renderer() const { return renderer_; }

 private:
  ScriptedPath path_;
  VirtualHandParams params_;
  MicrosClock clock_;
  DeviceCapabilities caps_;
  bool open_ = false;
  int64_t start_us_ = -1;
  int64_t last_us_ = -1;
  double x_[3] = {0.0, 0.0, 0.0};
  double v_[3] = {0.0, 0.0, 0.0};
  StaleCommand command_;
  SimRenderer renderer_{&command_, clock_};  // after command_ and clock_: stopped first
};

}  // namespace snapthread::device
