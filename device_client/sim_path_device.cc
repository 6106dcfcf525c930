#include "sim_path_device.h"

#include <utility>

namespace snapthread::device {

SimPathDevice::SimPathDevice(ScriptedPath path, MicrosClock clock)
    : SimulatedDevice(std::move(path), clock, "sim-path") {
  // Generous limits: a simulated device is limited by the scene's DeviceMapping.
  caps_.max_force_n = 10.0;
  caps_.max_stiffness_n_per_m = 2000.0;
  caps_.max_linear_damping_n_per_m_per_s = 20.0;
  // It keeps the commanded torque (last_torque_nm) as a real wrist would render it: a
  // torque-output device.
  caps_.has_torque_output = true;
  caps_.max_torque_nm = 1.0;
}

bool SimPathDevice::Open(std::string* error) {
  if (!HasClock(error)) return false;
  open_ = true;
  start_us_ = -1;
  return true;
}

bool SimPathDevice::Read(DeviceState* state) {
  if (!open_) return false;
  const int64_t now = clock_();
  if (start_us_ < 0) start_us_ = now;
  path_.Evaluate(1e-6 * static_cast<double>(now - start_us_), state->position_m,
                 state->velocity_m_per_s, state->orientation);
  state->buttons = 1;  // the scripted hand always holds the grasp
  return true;
}

bool SimPathDevice::Command(const double force_n[3], const double torque_nm[3]) {
  if (!open_) return false;
  for (int k = 0; k < 3; ++k) {
    last_force_n_[k] = force_n[k];
    last_torque_nm_[k] = torque_nm[k];
  }
  command_.Set(force_n, torque_nm, clock_());
  return true;
}

void SimPathDevice::Close() {
  for (double& f : last_force_n_) f = 0.0;
  for (double& t : last_torque_nm_) t = 0.0;
  if (clock_ != nullptr) command_.Clear(clock_());
  open_ = false;
}

}  // namespace snapthread::device
