// sim-path backend: the grasp follows a scripted path exactly (position and
// orientation) and ignores the commanded force and torque, keeping the last of each.
// Drives the server through a scene's snaps without hardware (demos, tests); it counts
// as a torque-output device so the torque half of the servo is exercised.
#pragma once

#include <cstdint>

#include "haptic_device.h"
#include "scripted_path.h"
#include "sim_clock.h"

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

 private:
  ScriptedPath path_;
  MicrosClock clock_;
  DeviceCapabilities caps_;
  int64_t start_us_ = -1;  // time of the first Read
  bool open_ = false;
  double last_force_n_[3] = {0.0, 0.0, 0.0};
  double last_torque_nm_[3] = {0.0, 0.0, 0.0};
};

}  // namespace snapthread::device
