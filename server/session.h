// The solve thread's session: the scene, its tracker and snap-ahead's fold boundary, and
// the steps of one equilibrium update for the poses the inbox handed over. Building a
// session and answering a pose with its grasp's force model are pure functions of the
// session here; when to do them and where the results go is the solve loop's
// (solve_loop.h).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "fold_boundary.h"
#include "scene/scene.h"
#include "server_inbox.h"
#include "snapthread/force_model_t.hpp"
#include "tracking/tracker.h"

namespace snapthread::server {

// What the server's flags change in every session it builds.
struct SessionSettings {
  std::string method;            // solver method override; "" = the scene's
  double time_budget_us = -1.0;  // per update (ServerParams::time_budget_us); < 0 = the scene's
  bool snap_ahead = true;        // --no-snap-ahead: false
};

struct Session {
  Scene scene;
  std::unique_ptr<EquilibriumTracker> tracker;
  // The grip direction of a device at rest (pose_mapping.h).
  Eigen::Vector3d rest_direction = Eigen::Vector3d::UnitX();
  // The scene's YAML as loaded, for checkpoints (empty without --state-dir).
  std::string scene_text;
  // Snap-ahead (docs/snap-ahead.md): null with --no-snap-ahead or several grasps.
  std::unique_ptr<FoldBoundary> fold;
};

// The scene with the settings applied, its tracker (MakeTracker) reset at the scene's
// grasp_start. SceneError for a scene whose grasp layout does not fit its model,
// std::invalid_argument for an unknown method.
std::unique_ptr<Session> MakeSession(const Scene& scene, const SessionSettings& settings);

// One update for a set of poses (the newest of each grasp).
struct SessionUpdate {
  Vec u;                        // the controls the poses moved the grasps to
  Vec renamed;                  // the tracker's controls under the names u continues
  std::vector<int> grasp_of;    // per pose: its grasp in scene.grasps, -1 = no such grasp
  bool any = false;             // some pose named a grasp (else nothing is solved)
  const TrackResult* result = nullptr;  // null: not solved, or the update threw
  bool failed = false;          // the update threw: error says what
  std::string error;
  double solve_us = 0.0;
  bool switched = false;        // started on the branch a snap-ahead switch chose
};

// Each pose moves its own grasp (grasp_poses.h); the others keep their controls.
SessionUpdate MapPoses(const Session& session, const std::vector<ReceivedPose>& poses);
// The tracker's update to update->u, timed: on the branch a device's snap-ahead switch
// chose when a pose says so, else from the controls renamed. Never throws (error).
void Solve(Session* session, const std::vector<ReceivedPose>& poses, SessionUpdate* update);
// Snap-ahead's search for the next fold from the new state, with the hand's orientation.
void FollowFold(Session* session, const std::vector<ReceivedPose>& poses,
                const SessionUpdate& update);

// The force model answering `pose`, for its grasp: that grasp's block of F and K
// (server_messages.h), the fold boundary and post-snap model when snap-ahead has them.
// Never invalid: a model that fails validation is replaced by a zero one (logged).
force_model_t GraspForceModel(const Session& session, const ReceivedPose& pose, int grasp,
                              const SessionUpdate& update, int64_t seq);

}  // namespace snapthread::server
