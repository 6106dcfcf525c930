// UNTESTED (no Force Dimension SDK or device here): see delta_device.h.
#include "delta_device.h"

#include <cmath>
#include <memory>
#include <string>

#include <Eigen/Geometry>

#include <dhdc.h>

#include "stale_command.h"

namespace snapthread::device {
namespace {

class DeltaDevice final : public HapticDevice {
 public:
  DeltaDevice() { caps_.model_name = "delta"; }
  ~DeltaDevice() override { Close(); }

  bool Open(std::string* error) override {
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
    // A wrist is sensed where the device has one (omega.6, sigma.7, delta.6) and torqued
    // where it is active (sigma.7, delta.6): dhdHasWrist / dhdHasActiveWrist. The SDK
    // gives no continuous wrist torque; 0.1 N m is an assumed bound, not a datasheet value.
    caps_.has_orientation = dhdHasWrist(id_);
    caps_.has_torque_output = dhdHasActiveWrist(id_);
    caps_.max_torque_nm = caps_.has_torque_output ? 0.1 : 0.0;
    // The controller's watchdog: forces off when no command came for 5 ms (40 x 125 us).
    constexpr int64_t kWatchdogUnitUs = 125;
    const auto watchdog =
        static_cast<unsigned char>(StaleCommand::kDefaultLimitUs / kWatchdogUnitUs);
    if (dhdSetWatchdog(watchdog, id_) < 0) {
      if (error) *error = std::string("dhdSetWatchdog: ") + dhdErrorGetLastStr();
      Close();
      return false;
    }
    if (dhdEnableForce(DHD_ON, id_) < 0) {
      if (error) *error = std::string("dhdEnableForce: ") + dhdErrorGetLastStr();
      Close();
      return false;
    }
    return true;
  }

  const DeviceCapabilities& capabilities() const override { return caps_; }

  bool Read(DeviceState* state) override {
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
    if (caps_.has_orientation) {
      double frame[3][3];
      if (dhdGetOrientationFrame(frame, id_) < 0) return false;
      Eigen::Matrix3d rot;
      for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) rot(i, j) = frame[i][j];
      }
      const Eigen::Quaterniond q(rot);
      state->orientation[0] = q.w();
      state->orientation[1] = q.x();
      state->orientation[2] = q.y();
      state->orientation[3] = q.z();
    }
    state->buttons = dhdGetButton(0, id_) == DHD_ON ? 1 : 0;
    return true;
  }

  bool Command(const double force_n[3], const double torque_nm[3]) override {
    if (id_ < 0) return false;
    if (caps_.has_torque_output) {
      // 0 or DHD_MOTOR_SATURATED on success, -1 on failure.
      return dhdSetForceAndTorque(force_n[0], force_n[1], force_n[2], torque_nm[0], torque_nm[1],
                                  torque_nm[2], id_) >= 0;
    }
    return dhdSetForce(force_n[0], force_n[1], force_n[2], id_) >= 0;
  }

  void Close() override {
    if (id_ < 0) return;
    if (caps_.has_torque_output) {
      dhdSetForceAndTorque(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, id_);
    } else {
      dhdSetForce(0.0, 0.0, 0.0, id_);
    }
    dhdClose(id_);
    id_ = -1;
  }

 private:
  DeviceCapabilities caps_;
  int id_ = -1;
};

}  // namespace

std::unique_ptr<HapticDevice> MakeDeltaDevice() { return std::make_unique<DeltaDevice>(); }

}  // namespace snapthread::device
