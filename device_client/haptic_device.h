// The haptic device backend interface of snapthread-device. Modelled on CHAI3D's
// cGenericHapticDevice / cHapticDeviceInfo: a capability struct with units and limits,
// and a device that is read and commanded once per servo tick. Every method is pure
// virtual: a backend that cannot do something must say so (return false + reason),
// never silently succeed.
#pragma once

#include <string>

namespace snapthread::device {

// What a device can do safely. The safety layer never exceeds these (nor the scene's
// DeviceMapping limits when those are smaller).
struct DeviceCapabilities {
  std::string model_name;                   // e.g. "virtual-hand", "PHANTOM Omni"
  double max_force_n = 0.0;                 // largest continuous force, newtons
  double max_stiffness_n_per_m = 0.0;       // largest stiffness stable at 1 kHz, N/m
  double max_linear_damping_n_per_m_per_s = 0.0;  // largest stable damping, N/(m/s)
  double workspace_radius_m = 0.0;          // radius of the usable workspace about the origin
  double max_velocity_m_per_s = 0.0;        // poses faster than this are suspect
  bool has_orientation = false;             // senses its orientation (DeviceState::orientation)
  // Renders a torque about the grip (Command's torque_nm): a wrist with motors (Force
  // Dimension sigma.7 / delta.6). A 3-DoF device (PHANToM Omni/Touch) senses its gimbal
  // but renders force only.
  bool has_torque_output = false;
  double max_torque_nm = 0.0;               // largest continuous torque, N m (torque output)
};

// One measurement, in the device frame (metres, origin at the workspace centre).
struct DeviceState {
  double position_m[3] = {0.0, 0.0, 0.0};
  double velocity_m_per_s[3] = {0.0, 0.0, 0.0};
  double orientation[4] = {1.0, 0.0, 0.0, 0.0};  // unit quaternion (w, x, y, z)
  int buttons = 0;                                // bit 0 = grasp held
};

class HapticDevice {
 public:
  virtual ~HapticDevice() = default;

  // Connects to the device and enables force output. False with a reason on failure.
  // Called once, off the servo thread; may allocate.
  virtual bool Open(std::string* error) = 0;
  // Valid after construction (simulated devices) or after Open (real ones).
  virtual const DeviceCapabilities& capabilities() const = 0;
  // Called every servo tick: must not allocate, log or block. False when the device
  // could not be read (the servo renders zero force for that tick).
  virtual bool Read(DeviceState* state) = 0;
  // Called every servo tick after Read: force on the user's hand [N] and torque about
  // the grip [N m], device frame. Must not allocate, log or block. False on failure.
  virtual bool Command(const double force_n[3], const double torque_nm[3]) = 0;
  // Commands zero force and releases the device. Idempotent.
  virtual void Close() = 0;
};

}  // namespace snapthread::device
