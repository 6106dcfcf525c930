// A scripted grasp path in device metres, traversed back and forth at constant speed:
// the input of the simulated backends (sim-path follows it exactly, virtual-hand is
// pulled along it by a spring). Waypoints may also turn the hand: a rotation vector per
// waypoint (radians, the device's rotation from rest; a rod scene's roll_deg), linear
// between waypoints as the scene's path is. A leg lasts the longer of its distance at
// the linear speed and its turn at the angular speed, so a path that only rolls the
// grasp (scenes/rod_greenhill.yaml) still moves.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "scene/scene.h"

namespace snapthread::device {

class ScriptedPath {
 public:
  // waypoints in metres (>= 1), speed > 0. Throws std::invalid_argument otherwise.
  ScriptedPath(std::vector<std::array<double, 3>> waypoints_m, double speed_m_per_s);
  // With a rotation vector per waypoint (same count) and the turning speed, rad/s > 0.
  ScriptedPath(std::vector<std::array<double, 3>> waypoints_m, std::vector<std::array<double, 3>> rotations,
               double speed_m_per_s, double angular_speed_rad_per_s);

  // The scene's grasp.path (or grasp.start when it has no path), model units, mapped to
  // device metres with messages::ControlsToPosition (planar scenes: on the model plane).
  // The path of scene grasp `grasp` (an index into scene.grasps; 0 for a single grasp),
  // in that grasp's device mapping.
  // A grasp that holds its orientation (the rod) turns as the path's rotation vectors
  // say (messages::ControlsToOrientation), at angular_speed_rad_per_s; a grip direction
  // (thread3d_loop) turns from each waypoint's direction to the next by the smallest
  // rotation (d = R(q) d_rest, messages::PoseToControls), whole turns accumulating.
  static ScriptedPath FromScene(const Scene& scene, double speed_m_per_s, int grasp = 0,
                                double angular_speed_rad_per_s = kDefaultAngularSpeed);
  // 45 degrees per second: rod_greenhill's buckle (515 degrees) in about 11 s.
  static constexpr double kDefaultAngularSpeed = 0.25 * 3.141592653589793;
  // A CSV file of positions in metres, one "x,y,z" (or "x,y") per line; lines starting
  // with '#' and a non-numeric header line are skipped. Throws std::runtime_error with the
  // file and line on a bad file.
  static ScriptedPath FromCsv(const std::string& path, double speed_m_per_s);

  // Position and velocity at time t_s >= 0 since the start (back and forth forever).
  // No allocation.
  void Evaluate(double t_s, double position_m[3], double velocity_m_per_s[3]) const;
  // The same and the orientation (w, x, y, z): exp of the interpolated rotation vector.
  void Evaluate(double t_s, double position_m[3], double velocity_m_per_s[3],
                double orientation[4]) const;

  double length_m() const { return total_length_m_; }
  // One pass from the first waypoint to the last, seconds (turning legs included).
  double duration_s() const { return total_time_s_; }
  const std::vector<std::array<double, 3>>& waypoints_m() const { return waypoints_; }
  // Largest distance of a waypoint from the origin, metres.
  double max_radius_m() const;

 private:
  std::vector<std::array<double, 3>> waypoints_;
  std::vector<std::array<double, 3>> rotations_;  // rotation vector at each waypoint
  std::vector<double> cumulative_s_;  // time at each waypoint, seconds
  double total_length_m_ = 0.0;
  double total_time_s_ = 0.0;
  double speed_m_per_s_;
  double angular_speed_rad_per_s_;
};

}  // namespace snapthread::device
