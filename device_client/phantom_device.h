// phantom backend: 3D Systems PHANToM / Touch through the OpenHaptics HD API.
// UNTESTED: compiled only when CMake finds HD/hd.h and libHD, and neither the SDK nor a
// device was available where this was written. The HD API only lets a device be read and
// commanded inside its own scheduler callback, so this backend runs an asynchronous HD
// callback at the HD servo rate that copies the pose into a LatestValue and applies the
// latest commanded force from a StaleCommand; Read/Command exchange with it wait-free.
// That adds up to one HD tick of latency; running ServoTick inside the HD callback instead
// would remove it. The callback is this backend's watchdog: it renders zero once the last
// command is older than StaleCommand::kDefaultLimitUs (a stalled servo thread), instead of
// the last force forever. OpenHaptics has no watchdog of its own to arm.
#pragma once

#include <atomic>

#include <HD/hd.h>

#include "haptic_device.h"
#include "realtime/latest_value.h"
#include "stale_command.h"

namespace snapthread::device {

class PhantomDevice final : public HapticDevice {
 public:
  PhantomDevice();
  ~PhantomDevice() override;

  bool Open(std::string* error) override;
  const DeviceCapabilities& capabilities() const override { return caps_; }
  bool Read(DeviceState* state) override;
  bool Command(const double force_n[3], const double torque_nm[3]) override;
  void Close() override;

 private:
  static HDCallbackCode HDCALLBACK ServoCallback(void* self);

  DeviceCapabilities caps_;
  HHD handle_ = HD_INVALID_HANDLE;
  HDSchedulerHandle callback_ = HD_INVALID_HANDLE;
  realtime::LatestValue<DeviceState> state_;  // HD thread -> servo thread
  StaleCommand command_;                       // servo thread -> HD thread
  std::atomic<bool> fault_{false};
  bool open_ = false;
};

}  // namespace snapthread::device
