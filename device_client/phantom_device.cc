// UNTESTED (no OpenHaptics SDK or device here): see phantom_device.h.
#include "phantom_device.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <memory>
#include <string>

#include <Eigen/Geometry>
#include <HD/hd.h>

#include "realtime/clock.h"
#include "realtime/latest_value.h"
#include "stale_command.h"

namespace snapthread::device {
namespace {

class PhantomDevice final : public HapticDevice {
 public:
  PhantomDevice() { caps_.model_name = "phantom"; }
  ~PhantomDevice() override { Close(); }

  bool Open(std::string* error) override {
    handle_ = hdInitDevice(HD_DEFAULT_DEVICE);
    HDErrorInfo err = hdGetError();
    if (HD_DEVICE_ERROR(err)) {
      if (error) *error = std::string("hdInitDevice: ") + hdGetErrorString(err.errorCode);
      return false;
    }
    hdMakeCurrentDevice(handle_);
    // Capabilities in HD units (mm, N, N/mm) converted to metres.
    HDdouble max_force = 0, max_stiffness = 0, max_damping = 0, workspace[6] = {0, 0, 0, 0, 0, 0};
    hdGetDoublev(HD_NOMINAL_MAX_CONTINUOUS_FORCE, &max_force);
    hdGetDoublev(HD_NOMINAL_MAX_STIFFNESS, &max_stiffness);
    hdGetDoublev(HD_NOMINAL_MAX_DAMPING, &max_damping);
    hdGetDoublev(HD_USABLE_WORKSPACE_DIMENSIONS, workspace);
    const char* model = hdGetString(HD_DEVICE_MODEL_TYPE);
    caps_.model_name = model ? model : "unknown";
    caps_.max_force_n = max_force;
    caps_.max_stiffness_n_per_m = 1000.0 * max_stiffness;           // N/mm -> N/m
    caps_.max_linear_damping_n_per_m_per_s = 1000.0 * max_damping;  // N s/mm -> N s/m
    double r = 0.0;
    for (int k = 0; k < 3; ++k) r = std::max(r, 0.5e-3 * std::abs(workspace[k + 3] - workspace[k]));
    caps_.workspace_radius_m = r;
    caps_.max_velocity_m_per_s = 1.0;
    // The gimbal is sensed (HD_CURRENT_TRANSFORM) but not torqued: a 3-DoF output device
    // renders the force of a rod's 6-DoF model with its rotation coupling, never a torque.
    caps_.has_orientation = true;
    caps_.has_torque_output = false;
    hdEnable(HD_FORCE_OUTPUT);
    hdEnable(HD_MAX_FORCE_CLAMPING);
    callback_ = hdScheduleAsynchronous(&PhantomDevice::ServoCallback, this,
                                       HD_DEFAULT_SCHEDULER_PRIORITY);
    hdStartScheduler();
    err = hdGetError();
    if (HD_DEVICE_ERROR(err)) {
      if (error) *error = std::string("hdStartScheduler: ") + hdGetErrorString(err.errorCode);
      Close();
      return false;
    }
    open_ = true;
    return true;
  }

  const DeviceCapabilities& capabilities() const override { return caps_; }

  bool Read(DeviceState* state) override {
    if (!open_ || fault_.load(std::memory_order_relaxed)) return false;
    return state_.Read(state);
  }

  bool Command(const double force_n[3], const double /*torque_nm*/[3]) override {
    if (!open_ || fault_.load(std::memory_order_relaxed)) return false;
    command_.Set(force_n, nullptr, realtime::MonotonicMicros());
    return true;
  }

  void Close() override {
    if (handle_ == HD_INVALID_HANDLE) return;
    command_.Clear(realtime::MonotonicMicros());
    hdStopScheduler();
    if (callback_ != HD_INVALID_HANDLE) hdUnschedule(callback_);
    hdDisable(HD_FORCE_OUTPUT);
    hdDisableDevice(handle_);
    handle_ = HD_INVALID_HANDLE;
    callback_ = HD_INVALID_HANDLE;
    open_ = false;
  }

 private:
  // The HD scheduler's callback, at the HD servo rate: reads the pose into state_ and
  // renders the latest fresh command.
  static HDCallbackCode HDCALLBACK ServoCallback(void* self_ptr) {
    auto* self = static_cast<PhantomDevice*>(self_ptr);
    hdBeginFrame(self->handle_);
    HDdouble pos_mm[3], vel_mm_s[3], transform[16];
    HDint buttons = 0;
    hdGetDoublev(HD_CURRENT_POSITION, pos_mm);
    hdGetDoublev(HD_CURRENT_VELOCITY, vel_mm_s);
    hdGetDoublev(HD_CURRENT_TRANSFORM, transform);
    hdGetIntegerv(HD_CURRENT_BUTTONS, &buttons);
    DeviceState s;
    for (int k = 0; k < 3; ++k) {
      s.position_m[k] = 1e-3 * pos_mm[k];
      s.velocity_m_per_s[k] = 1e-3 * vel_mm_s[k];
    }
    // Rotation (column-major 4x4) -> quaternion (w, x, y, z); Eigen's conversion is exact
    // at every angle (half a turn included).
    Eigen::Matrix3d rot;
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) rot(i, j) = transform[4 * j + i];
    }
    const Eigen::Quaterniond q(rot);
    s.orientation[0] = q.w();
    s.orientation[1] = q.x();
    s.orientation[2] = q.y();
    s.orientation[3] = q.z();
    s.buttons = buttons;
    self->state_.Write(s);
    // The last command while it is fresh, else zero (the servo thread stalled).
    HDdouble force[3];
    double torque[3];
    self->command_.Output(realtime::MonotonicMicros(), force, torque);
    hdSetDoublev(HD_CURRENT_FORCE, force);
    hdEndFrame(self->handle_);
    HDErrorInfo err = hdGetError();
    if (HD_DEVICE_ERROR(err)) {
      self->fault_.store(true);
      return HD_CALLBACK_DONE;
    }
    return HD_CALLBACK_CONTINUE;
  }

  DeviceCapabilities caps_;
  HHD handle_ = HD_INVALID_HANDLE;
  HDSchedulerHandle callback_ = HD_INVALID_HANDLE;
  realtime::LatestValue<DeviceState> state_;  // HD thread -> servo thread
  StaleCommand command_;                       // servo thread -> HD thread
  std::atomic<bool> fault_{false};
  bool open_ = false;
};

}  // namespace

std::unique_ptr<HapticDevice> MakePhantomDevice() { return std::make_unique<PhantomDevice>(); }

}  // namespace snapthread::device
