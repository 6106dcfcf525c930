// sim-path backend: the grasp follows a scripted path exactly (position and
// orientation) and ignores the commanded force and torque, keeping the last of each.
// What it would render goes through its StaleCommand and render thread
// (simulated_device.h). Drives the server through a scene's snaps without hardware
// (demos, tests); it counts as a torque-output device so the torque half of the servo is
// exercised.
#pragma once

#include <cstdint>

#include "simulated_device.h"

namespace snapthread::device {

class SimPathDevice final : public SimulatedDevice {
 public:
  SimPathDevice(ScriptedPath path, MicrosClock clock);

  bool Open(std::string* error) override;
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

 private:
  double last_force_n_[3] = {0.0, 0.0, 0.0};
  double last_torque_nm_[3] = {0.0, 0.0, 0.0};
};

}  // namespace snapthread::device
