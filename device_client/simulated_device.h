// What the simulated backends (sim-path, virtual-hand) share: a scripted path to follow, a
// clock, capabilities of a generous desktop device that senses the path's orientation,
// and what they render: the last command through a StaleCommand (zero once it is older
// than 5 ms, as a real backend's watchdog does), published by their "firmware" render
// thread (sim_renderer.h; renderer().Start, --sim-render-file).
#pragma once

#include <cstdint>
#include <string>

#include "haptic_device.h"
#include "scripted_path.h"
#include "sim_clock.h"
#include "sim_renderer.h"
#include "stale_command.h"

namespace snapthread::device {

class SimulatedDevice : public HapticDevice {
 public:
  const DeviceCapabilities& capabilities() const final { return caps_; }
  const StaleCommand& command() const { return command_; }
  // The render thread: not running until Start ("" = record in memory only).
  SimRenderer& renderer() { return renderer_; }
  const SimRenderer& renderer() const { return renderer_; }

 protected:
  // caps_ gets model_name and what both simulated devices share (workspace, speed,
  // orientation sensed); the backend sets its force, stiffness and torque limits.
  SimulatedDevice(ScriptedPath path, MicrosClock clock, const char* model_name);
  // Open's common part: false with "<model>: no clock" when there is no clock.
  bool HasClock(std::string* error) const;

  ScriptedPath path_;
  MicrosClock clock_;
  DeviceCapabilities caps_;
  bool open_ = false;
  int64_t start_us_ = -1;  // time of the first Read
  StaleCommand command_;
  SimRenderer renderer_{&command_, clock_};  // after command_ and clock_: stopped first
};

}  // namespace snapthread::device
