// delta backend: Force Dimension delta / omega / sigma through the DHD SDK.
// UNTESTED: compiled only when CMake finds dhdc.h and libdhd, and neither the SDK nor a
// device was available where this was written. DHD calls are synchronous USB
// transactions (~0.1-0.2 ms), made directly from the servo thread. Devices with a wrist
// report their orientation (dhdGetOrientationFrame); those with an active wrist (sigma.7,
// delta.6) render the grip torque too (dhdSetForceAndTorque). Also untested.
// Watchdog: Open arms the controller's own (dhdSetWatchdog, in units of 125 us) at
// StaleCommand::kDefaultLimitUs, so the controller drops the force if the servo thread
// stops commanding (stalled, or the process stopped). Also untested: no SDK here.
// The device is one class local to delta_device.cc: callers need only the HapticDevice
// interface, and this header stays free of the SDK's.
#pragma once

#include <memory>

#include "haptic_device.h"

namespace snapthread::device {

// A Force Dimension device, closed: Open connects to the first one DHD finds.
std::unique_ptr<HapticDevice> MakeDeltaDevice();

}  // namespace snapthread::device
