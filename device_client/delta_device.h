// delta backend: Force Dimension delta / omega / sigma through the DHD SDK.
// UNTESTED: compiled only when CMake finds dhdc.h and libdhd, and neither the SDK nor a
// device was available where this was written. DHD calls are synchronous USB
// transactions (~0.1-0.2 ms), made directly from the servo thread. Devices with a wrist
// report their orientation (dhdGetOrientationFrame); those with an active wrist (sigma.7,
// delta.6) render the grip torque too (dhdSetForceAndTorque). Also untested.
// Watchdog: Open arms the controller's own (dhdSetWatchdog, in units of 125 us) at
// StaleCommand::kDefaultLimitUs, so the controller drops the force if the servo thread
// stops commanding (stalled, or the process stopped). Also untested: no SDK here.
#pragma once

#include "haptic_device.h"

namespace snapthread::device {

class DeltaDevice final : public HapticDevice {
 public:
  DeltaDevice();
  ~DeltaDevice() override;

  bool Open(std::string* error) override;
  const DeviceCapabilities& capabilities() const override { return caps_; }
  bool Read(DeviceState* state) override;
  bool Command(const double force_n[3], const double torque_nm[3]) override;
  void Close() override;

 private:
  DeviceCapabilities caps_;
  int id_ = -1;
};

}  // namespace snapthread::device
