#include "scripted_path.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include <Eigen/Geometry>

#include "messages/pose_mapping.h"
#include "numeric/so3.h"
#include "scene/input_file.h"

namespace snapthread::device {
namespace {

constexpr std::size_t kMaxPathCsvBytes = std::size_t{16} << 20;

}  // namespace

ScriptedPath::ScriptedPath(std::vector<std::array<double, 3>> waypoints_m, double speed_m_per_s)
    : ScriptedPath(waypoints_m, std::vector<std::array<double, 3>>(waypoints_m.size(), {0.0, 0.0, 0.0}),
                   speed_m_per_s, 1.0) {}

ScriptedPath::ScriptedPath(std::vector<std::array<double, 3>> waypoints_m,
                           std::vector<std::array<double, 3>> rotations, double speed_m_per_s,
                           double angular_speed_rad_per_s)
    : waypoints_(std::move(waypoints_m)),
      rotations_(std::move(rotations)),
      speed_m_per_s_(speed_m_per_s),
      angular_speed_rad_per_s_(angular_speed_rad_per_s) {
  if (waypoints_.empty()) throw std::invalid_argument("scripted path: no waypoints");
  if (rotations_.size() != waypoints_.size())
    throw std::invalid_argument("scripted path: one rotation per waypoint");
  if (!(speed_m_per_s > 0.0) || !std::isfinite(speed_m_per_s)) {
    throw std::invalid_argument("scripted path: speed must be positive");
  }
  if (!(angular_speed_rad_per_s > 0.0) || !std::isfinite(angular_speed_rad_per_s)) {
    throw std::invalid_argument("scripted path: angular speed must be positive");
  }
  for (size_t i = 0; i < waypoints_.size(); ++i) {
    for (int k = 0; k < 3; ++k) {
      if (!std::isfinite(waypoints_[i][k]) || !std::isfinite(rotations_[i][k]))
        throw std::invalid_argument("scripted path: non-finite waypoint");
    }
  }
  cumulative_s_.push_back(0.0);
  for (size_t i = 1; i < waypoints_.size(); ++i) {
    double d2 = 0.0, a2 = 0.0;
    for (int k = 0; k < 3; ++k) {
      const double d = waypoints_[i][k] - waypoints_[i - 1][k];
      const double a = rotations_[i][k] - rotations_[i - 1][k];
      d2 += d * d;
      a2 += a * a;
    }
    total_length_m_ += std::sqrt(d2);
    cumulative_s_.push_back(cumulative_s_.back() +
                            std::max(std::sqrt(d2) / speed_m_per_s_, std::sqrt(a2) / angular_speed_rad_per_s_));
  }
  total_time_s_ = cumulative_s_.back();
}

ScriptedPath ScriptedPath::FromScene(const Scene& scene, double speed_m_per_s, int grasp,
                                     double angular_speed_rad_per_s) {
  std::vector<std::array<double, 3>> pts, rotations;
  const DeviceMapping mapping = GraspDeviceMapping(scene, grasp);
  const int m = scene.grasp_layout.NumControls();
  const int offset = grasp > 0 && grasp < static_cast<int>(scene.grasps.size()) ? scene.grasps[grasp].offset : 0;
  const int dim = scene.grasp_layout.spatial_dimension;
  const Eigen::Vector3d rest = messages::RestGripDirection(scene);
  Eigen::Matrix3d turned = Eigen::Matrix3d::Identity();  // grip direction layouts: R so far
  Eigen::Vector3d last_r = Eigen::Vector3d::Zero();
  auto add = [&](const Vec& controls) {
    const Vec control = controls.size() >= offset + m ? Vec(controls.segment(offset, m)) : controls;
    const Eigen::Vector3d p = messages::ControlsToPosition(mapping, scene.grasp_layout, control);
    pts.push_back({p[0], p[1], p[2]});
    // The rotation vector as the pose mapping sends it back (exp of it: the device's
    // rotation from rest); kept as the path's own value so whole turns accumulate.
    std::array<double, 3> r = {0.0, 0.0, 0.0};
    if (scene.grasp_layout.grip_rotation && control.size() >= dim + 3) {
      for (int k = 0; k < 3; ++k) r[k] = control[dim + k];
    } else if (scene.grasp_layout.grip_direction && control.size() >= dim + 3) {
      // A grip direction d = R(q) d_rest (pose_mapping.h): the hand turns from the last
      // waypoint's direction to this one by the smallest rotation, and the rotation
      // vector continues the last one (whole turns accumulate, thread3d_loop's 720
      // degrees), so the path turns the grip through the scene's directions.
      turned = so3::SmallestRotation(turned * rest, control.segment<3>(dim)) * turned;
      const Eigen::Quaterniond q(turned);
      last_r = so3::NearestRepresentative(so3::LogQuaternion(q.w(), q.x(), q.y(), q.z()), last_r);
      for (int k = 0; k < 3; ++k) r[k] = last_r[k];
    }
    rotations.push_back(r);
  };
  if (scene.path.empty()) {
    add(scene.grasp_start);
  } else {
    for (const Vec& p : scene.path) add(p);
  }
  return ScriptedPath(std::move(pts), std::move(rotations), speed_m_per_s, angular_speed_rad_per_s);
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
  double orientation[4];
  Evaluate(t_s, position_m, velocity_m_per_s, orientation);
}

void ScriptedPath::Evaluate(double t_s, double position_m[3], double velocity_m_per_s[3],
                            double orientation[4]) const {
  double r[3];
  for (int k = 0; k < 3; ++k) {
    position_m[k] = waypoints_.front()[k];
    velocity_m_per_s[k] = 0.0;
    r[k] = rotations_.front()[k];
  }
  if (waypoints_.size() >= 2 && total_time_s_ > 0.0 && t_s >= 0.0) {
    // Back and forth: the time along the path is a triangle wave of period 2T.
    const double period_s = 2.0 * total_time_s_;
    double s = std::fmod(t_s, period_s);
    double direction = 1.0;
    if (s > total_time_s_) {
      s = period_s - s;
      direction = -1.0;
    }
    size_t i = 1;
    while (i + 1 < cumulative_s_.size() && cumulative_s_[i] < s) ++i;
    const double seg = cumulative_s_[i] - cumulative_s_[i - 1];
    const double a = seg > 0.0 ? (s - cumulative_s_[i - 1]) / seg : 0.0;
    for (int k = 0; k < 3; ++k) {
      const double d = waypoints_[i][k] - waypoints_[i - 1][k];
      position_m[k] = waypoints_[i - 1][k] + a * d;
      velocity_m_per_s[k] = seg > 0.0 ? direction * d / seg : 0.0;
      r[k] = rotations_[i - 1][k] + a * (rotations_[i][k] - rotations_[i - 1][k]);
    }
  }
  const Eigen::Vector4d q = so3::ExpQuaternion(Eigen::Vector3d(r[0], r[1], r[2]));
  for (int k = 0; k < 4; ++k) orientation[k] = q[k];
}

double ScriptedPath::max_radius_m() const {
  double r = 0.0;
  for (const auto& w : waypoints_) {
    r = std::max(r, std::sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]));
  }
  return r;
}

}  // namespace snapthread::device
