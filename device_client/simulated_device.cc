#include "simulated_device.h"

#include <utility>

namespace snapthread::device {

SimulatedDevice::SimulatedDevice(ScriptedPath path, MicrosClock clock, const char* model_name)
    : path_(std::move(path)), clock_(clock) {
  caps_.model_name = model_name;
  caps_.workspace_radius_m = 0.25;
  caps_.max_velocity_m_per_s = 2.0;
  // The hand turns as the path says (a rod scene's roll).
  caps_.has_orientation = true;
}

bool SimulatedDevice::HasClock(std::string* error) const {
  if (clock_ != nullptr) return true;
  if (error) *error = caps_.model_name + ": no clock";
  return false;
}

}  // namespace snapthread::device
