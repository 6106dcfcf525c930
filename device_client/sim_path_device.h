// sim-path backend: the grasp follows a scripted path exactly (position and
// orientation) and ignores the commanded force and torque, keeping the last of each.
// What it would render goes through a StaleCommand (zero once the command is older than
// 5 ms, as a real backend's watchdog does); StartRenderer runs its "firmware" thread,
// which publishes that rendered output (sim_renderer.h).
// Drives the server through a scene's snaps without hardware (demos, tests); it counts
// as a torque-output device so the torque half of the servo is exercised.
#pragma once

#include <cstdint>

#include "haptic_device.h"
#include "scripted_path.h"
#include "sim_clock.h"
#include "sim_renderer.h"
#include "stale_command.h"

namespace snapthread::device {

class SimPathDevice final : public HapticDevice {
 public:
  SimPathDevice(ScriptedPath path, MicrosClock clock);

  bool Open(std::string* error) override;
  const DeviceCapabilities& capabilities() const override { return caps_; }
  bool Read(DeviceState* state) override;
  bool Command(const double force_n[3], const double torque_nm[3]) override;
  void Close() override;

  // The force of the last Command (what a real device would have rendered), newtons.
  const double* last_force_n() const { return last_force_n_; }
  // The torque of the last Command, newton metres.
  const double* last_torque_nm() const { return last_torque_nm_; }
  // What the device renders at now_us: the last command, or zero once it is stale.
  bool Rendered(int64_t now_us, double force_n[3], double torque_nm[3]) const {
    return command_.Output(now_us, force_n, torque_nm);
  }
  const StaleCommand& command() const { return command_; }
  // Starts the render thread ("" = record in memory only); see SimRenderer::Start.
  bool StartRenderer(const std::string& shared_file, std::string* error) {
    return renderer_.Start(shared_file, error);
  }
  const SimRenderer& renderer() const { return renderer_; }

 private:
  ScriptedPath path_;
  MicrosClock clock_;
  DeviceCapabilities caps_;
  int64_t start_us_ = -1;  // time of the first Read
  bool open_ = false;
  double last_force_n_[3] = {0.0, 0.0, 0.0};
  double last_torque_nm_[3] = {0.0, 0.0, 0.0};
  StaleCommand command_;
  SimRenderer renderer_{&command_, clock_};  // after command_ and clock_: stopped first
};

}  // namespace snapthread::device
