#include "virtual_hand_device.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace snapthread::device {

VirtualHandDevice::VirtualHandDevice(ScriptedPath path, VirtualHandParams params,
                                     MicrosClock clock)
    : SimulatedDevice(std::move(path), clock, "virtual-hand"), params_(params) {
  caps_.max_force_n = 8.0;
  // Semi-implicit Euler of the mass at 1 kHz is stable for w dt < 2; keep w dt <= 0.3:
  // k_max = m (0.3 / dt)^2 = 0.1 * 300^2 = 9000 N/m. The device claims far less, like a
  // desktop device, so the safety clamp is what acts.
  caps_.max_stiffness_n_per_m = 1500.0;
  caps_.max_linear_damping_n_per_m_per_s = 10.0;
  // No rotational dynamics: it renders no torque.
  caps_.has_torque_output = false;
}

bool VirtualHandDevice::Open(std::string* error) {
  if (!HasClock(error)) return false;
  if (!(params_.mass_kg > 0.0) || !(params_.spring_n_per_m >= 0.0) ||
      !(params_.max_substep_s > 0.0)) {
    if (error) *error = "virtual-hand: mass and substep must be positive, spring >= 0";
    return false;
  }
  double v[3];
  path_.Evaluate(0.0, x_, v);
  for (int k = 0; k < 3; ++k) v_[k] = 0.0;
  start_us_ = last_us_ = -1;
  open_ = true;
  return true;
}

void VirtualHandDevice::Integrate(double t_s, double dt_s) {
  const double m = params_.mass_kg;
  const double k = params_.spring_n_per_m;
  const double c = 2.0 * params_.damping_ratio * std::sqrt(k * m);
  dt_s = std::min(dt_s, params_.max_dt_s);
  const int steps = std::max(1, static_cast<int>(std::ceil(dt_s / params_.max_substep_s)));
  const double h = dt_s / steps;
  for (int s = 0; s < steps; ++s) {
    const double t = t_s - dt_s + (s + 1) * h;
    double target[3], target_v[3];
    path_.Evaluate(t, target, target_v);
    // The force the device renders at this substep: zero once the command is stale.
    double force[3], torque[3];
    command_.Output(start_us_ + static_cast<int64_t>(std::llround(1e6 * t)), force, torque);
    for (int i = 0; i < 3; ++i) {
      // Spring-damper toward the intended motion plus the rendered force on the hand.
      const double a = (k * (target[i] - x_[i]) + c * (target_v[i] - v_[i]) + force[i]) / m;
      v_[i] += h * a;
      x_[i] += h * v_[i];
    }
  }
}

bool VirtualHandDevice::Read(DeviceState* state) {
  if (!open_) return false;
  const int64_t now = clock_();
  if (start_us_ < 0) start_us_ = last_us_ = now;
  const double dt = 1e-6 * static_cast<double>(now - last_us_);
  if (dt > 0.0) Integrate(1e-6 * static_cast<double>(now - start_us_), dt);
  last_us_ = now;
  for (int k = 0; k < 3; ++k) {
    state->position_m[k] = x_[k];
    state->velocity_m_per_s[k] = v_[k];
  }
  double target[3], target_v[3];
  path_.Evaluate(1e-6 * static_cast<double>(now - start_us_), target, target_v, state->orientation);
  state->buttons = 1;
  return true;
}

bool VirtualHandDevice::Command(const double force_n[3], const double /*torque_nm*/[3]) {
  if (!open_) return false;
  command_.Set(force_n, nullptr, clock_());  // no torque output
  return true;
}

void VirtualHandDevice::Close() {
  if (clock_ != nullptr) command_.Clear(clock_());
  open_ = false;
}

}  // namespace snapthread::device
