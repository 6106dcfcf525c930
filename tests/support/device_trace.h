// snapthread-device's --trace file read back (device_client.cc writes it: one row a
// traced servo tick), for the process tests that check what the device rendered.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

namespace snapthread::test_support {

struct DeviceTraceRow {
  double t_s = 0.0;  // since the device started
  long long tick = 0;
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d force_n = Eigen::Vector3d::Zero();
  double model_age_ms = -1.0;  // < 0: no model yet
  int model_status = -1;       // force_model_t::STATUS_*
  bool clamped = false;
  bool fading = false;
  Eigen::Vector4d orientation = Eigen::Vector4d(1.0, 0.0, 0.0, 0.0);  // (w, x, y, z)
  Eigen::Vector3d torque_nm = Eigen::Vector3d::Zero();
};

// The rows of the trace at `path` (the header skipped); a line that is not a whole row
// (one cut off by a kill) is left out.
std::vector<DeviceTraceRow> ReadDeviceTrace(const std::string& path);

}  // namespace snapthread::test_support
