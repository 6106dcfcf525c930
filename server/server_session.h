// The solve thread's session: the scene and its tracker (server.cc, commands.cc).
#pragma once

#include <memory>
#include <string>

#include <Eigen/Core>

#include "fold_boundary.h"
#include "scene/scene.h"
#include "server.h"
#include "tracking/tracker.h"

namespace snapthread::server {

struct Server::Session {
  Scene scene;
  std::unique_ptr<EquilibriumTracker> tracker;
  // The grip direction of a device at rest (pose_mapping.h).
  Eigen::Vector3d rest_direction = Eigen::Vector3d::UnitX();
  // The scene's YAML as loaded, for checkpoints (empty without --state-dir).
  std::string scene_text;
  // Snap-ahead (issue 17): null with --no-snap-ahead.
  std::unique_ptr<FoldBoundary> fold;
};

}  // namespace snapthread::server
