#include "scripted_path.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "messages/pose_mapping.h"
#include "scene/input_file.h"

namespace snapthread::device {
namespace {

constexpr std::size_t kMaxPathCsvBytes = std::size_t{16} << 20;

}  // namespace

ScriptedPath::ScriptedPath(std::vector<std::array<double, 3>> waypoints_m, double speed_m_per_s)
    : waypoints_(std::move(waypoints_m)), speed_m_per_s_(speed_m_per_s) {
  if (waypoints_.empty()) throw std::invalid_argument("scripted path: no waypoints");
  if (!(speed_m_per_s > 0.0) || !std::isfinite(speed_m_per_s)) {
    throw std::invalid_argument("scripted path: speed must be positive");
  }
  cumulative_m_.push_back(0.0);
  for (size_t i = 1; i < waypoints_.size(); ++i) {
    double d2 = 0.0;
    for (int k = 0; k < 3; ++k) {
      const double d = waypoints_[i][k] - waypoints_[i - 1][k];
      d2 += d * d;
    }
    cumulative_m_.push_back(cumulative_m_.back() + std::sqrt(d2));
  }
  for (const auto& w : waypoints_) {
    for (double c : w) {
      if (!std::isfinite(c)) throw std::invalid_argument("scripted path: non-finite waypoint");
    }
  }
  total_length_m_ = cumulative_m_.back();
}

ScriptedPath ScriptedPath::FromScene(const Scene& scene, double speed_m_per_s, int grasp) {
  std::vector<std::array<double, 3>> pts;
  const DeviceMapping mapping = GraspDeviceMapping(scene, grasp);
  const int m = scene.grasp_layout.NumControls();
  const int offset = grasp > 0 && grasp < static_cast<int>(scene.grasps.size()) ? scene.grasps[grasp].offset : 0;
  auto add = [&](const Vec& controls) {
    const Vec control = controls.size() >= offset + m ? Vec(controls.segment(offset, m)) : controls;
    const Eigen::Vector3d p = messages::ControlsToPosition(mapping, scene.grasp_layout, control);
    pts.push_back({p[0], p[1], p[2]});
  };
  if (scene.path.empty()) {
    add(scene.grasp_start);
  } else {
    for (const Vec& p : scene.path) add(p);
  }
  return ScriptedPath(std::move(pts), speed_m_per_s);
}

ScriptedPath ScriptedPath::FromCsv(const std::string& path, double speed_m_per_s) {
  // Bounded and non-blocking (a FIFO or /dev/zero is refused, not waited on); a path of
  // 16 MiB is over 500k waypoints.
  std::istringstream in(ReadInputFile(path, kMaxPathCsvBytes, "path CSV"));
  std::vector<std::array<double, 3>> pts;
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.empty() || line[0] == '#') continue;
    std::stringstream ss(line);
    std::array<double, 3> p = {0.0, 0.0, 0.0};
    std::string cell;
    int k = 0;
    bool numeric = true;
    while (std::getline(ss, cell, ',') && k < 3) {
      try {
        size_t used = 0;
        p[k] = std::stod(cell, &used);
      } catch (const std::exception&) {
        numeric = false;
        break;
      }
      ++k;
    }
    if (!numeric) {
      if (pts.empty() && line_no == 1) continue;  // header line
      throw std::runtime_error(path + ":" + std::to_string(line_no) +
                               ": expected numbers x,y[,z] in metres");
    }
    if (k < 2) {
      throw std::runtime_error(path + ":" + std::to_string(line_no) +
                               ": expected at least two columns x,y");
    }
    pts.push_back(p);
  }
  if (pts.empty()) throw std::runtime_error(path + ": no positions");
  return ScriptedPath(std::move(pts), speed_m_per_s);
}

void ScriptedPath::Evaluate(double t_s, double position_m[3], double velocity_m_per_s[3]) const {
  for (int k = 0; k < 3; ++k) {
    position_m[k] = waypoints_.front()[k];
    velocity_m_per_s[k] = 0.0;
  }
  if (waypoints_.size() < 2 || total_length_m_ <= 0.0 || !(t_s >= 0.0)) return;
  // Back and forth: the arc-length coordinate is a triangle wave of period 2L/v.
  const double period_m = 2.0 * total_length_m_;
  double s = std::fmod(t_s * speed_m_per_s_, period_m);
  double direction = 1.0;
  if (s > total_length_m_) {
    s = period_m - s;
    direction = -1.0;
  }
  size_t i = 1;
  while (i + 1 < cumulative_m_.size() && cumulative_m_[i] < s) ++i;
  const double seg = cumulative_m_[i] - cumulative_m_[i - 1];
  const double a = seg > 0.0 ? (s - cumulative_m_[i - 1]) / seg : 0.0;
  for (int k = 0; k < 3; ++k) {
    const double d = waypoints_[i][k] - waypoints_[i - 1][k];
    position_m[k] = waypoints_[i - 1][k] + a * d;
    velocity_m_per_s[k] = seg > 0.0 ? direction * speed_m_per_s_ * d / seg : 0.0;
  }
}

double ScriptedPath::max_radius_m() const {
  double r = 0.0;
  for (const auto& w : waypoints_) {
    r = std::max(r, std::sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]));
  }
  return r;
}

}  // namespace snapthread::device
