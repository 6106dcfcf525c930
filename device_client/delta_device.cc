// UNTESTED (no Force Dimension SDK or device here): see delta_device.h.
#include "delta_device.h"

#include <cmath>

#include <dhdc.h>

namespace snapthread::device {

DeltaDevice::DeltaDevice() { caps_.model_name = "delta"; }

DeltaDevice::~DeltaDevice() { Close(); }

bool DeltaDevice::Open(std::string* error) {
  id_ = dhdOpen();
  if (id_ < 0) {
    if (error) *error = std::string("dhdOpen: ") + dhdErrorGetLastStr();
    return false;
  }
  const char* name = dhdGetSystemName(id_);
  caps_.model_name = name ? name : "unknown";
  // The SDK does not report these; conservative values for a delta.3 / omega.3 at 1 kHz.
  caps_.max_force_n = 12.0;
  caps_.max_stiffness_n_per_m = 2000.0;
  caps_.max_linear_damping_n_per_m_per_s = 20.0;
  caps_.workspace_radius_m = 0.075;
  caps_.max_velocity_m_per_s = 1.0;
  caps_.has_orientation = false;  // forces only; wrist torques not driven
  if (dhdEnableForce(DHD_ON, id_) < 0) {
    if (error) *error = std::string("dhdEnableForce: ") + dhdErrorGetLastStr();
    Close();
    return false;
  }
  return true;
}

bool DeltaDevice::Read(DeviceState* state) {
  if (id_ < 0) return false;
  double p[3], v[3];
  if (dhdGetPosition(&p[0], &p[1], &p[2], id_) < 0) return false;
  if (dhdGetLinearVelocity(&v[0], &v[1], &v[2], id_) < 0) return false;
  for (int k = 0; k < 3; ++k) {
    state->position_m[k] = p[k];
    state->velocity_m_per_s[k] = v[k];
  }
  state->orientation[0] = 1.0;
  state->orientation[1] = state->orientation[2] = state->orientation[3] = 0.0;
  state->buttons = dhdGetButton(0, id_) == DHD_ON ? 1 : 0;
  return true;
}

bool DeltaDevice::Command(const double force_n[3], const double /*torque_nm*/[3]) {
  if (id_ < 0) return false;
  return dhdSetForce(force_n[0], force_n[1], force_n[2], id_) >= 0;
}

void DeltaDevice::Close() {
  if (id_ < 0) return;
  dhdSetForce(0.0, 0.0, 0.0, id_);
  dhdClose(id_);
  id_ = -1;
}

}  // namespace snapthread::device
