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
// The device is one class local to phantom_device.cc: callers need only the HapticDevice
// interface, and this header stays free of the SDK's.
#pragma once

#include <memory>

#include "haptic_device.h"

namespace snapthread::device {

// A PHANToM / Touch, closed: Open initialises the default HD device and starts the HD
// scheduler with this backend's callback.
std::unique_ptr<HapticDevice> MakePhantomDevice();

}  // namespace snapthread::device
