#include "device_trace.h"

#include <cstdio>
#include <fstream>

namespace snapthread::test_support {

std::vector<DeviceTraceRow> ReadDeviceTrace(const std::string& path) {
  std::vector<DeviceTraceRow> rows;
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);  // header
  while (std::getline(in, line)) {
    DeviceTraceRow r;
    int clamped = 0, fading = 0;
    double* p = r.position_m.data();
    double* f = r.force_n.data();
    double* q = r.orientation.data();
    double* t = r.torque_nm.data();
    if (std::sscanf(line.c_str(), "%lf,%lld,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%d,%d,%d,%lf,%lf,%lf,%lf,%lf,%lf,%lf",
                    &r.t_s, &r.tick, &p[0], &p[1], &p[2], &f[0], &f[1], &f[2], &r.model_age_ms,
                    &r.model_status, &clamped, &fading, &q[0], &q[1], &q[2], &q[3], &t[0], &t[1],
                    &t[2]) == 19) {
      r.clamped = clamped != 0;
      r.fading = fading != 0;
      rows.push_back(r);
    }
  }
  return rows;
}

}  // namespace snapthread::test_support
