#include "shape_frames.h"

#include "models/frames_capability.h"

namespace snapthread::server {

void FillShapeFrames(const Model& model, const Vec& x, const Vec& u, thread_shape_t* msg) {
  msg->num_frames = 0;
  msg->frames.clear();
  const FramesCapability* frames = model.frames();
  if (frames == nullptr || x.size() != model.NumStates() || u.size() != model.NumControls()) return;
  Eigen::Matrix3Xd d1;
  Vec density;
  frames->MaterialFrames(x, u, &d1, &density);
  // A frame that is not finite is not drawable: send none rather than a made-up one.
  if (!d1.allFinite() || !density.allFinite()) return;
  msg->frames.reserve(static_cast<size_t>(d1.cols()));
  for (Eigen::Index j = 0; j < d1.cols(); ++j) {
    msg->frames.push_back({d1(0, j), d1(1, j), d1(2, j), density[j]});
  }
  msg->num_frames = static_cast<int32_t>(msg->frames.size());
}

}  // namespace snapthread::server
