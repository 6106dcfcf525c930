#include "knot_watch.h"

#include <limits>
#include <utility>
#include <vector>

#include "models/registry.h"

namespace snapthread::server {

void KnotWatch::Reset() {
  ++generation_;
  name_.clear();
  determinant_ = 0;
  next_ = Clock::time_point{};
}

void KnotWatch::Tick(Clock::time_point now, const Scene& scene,
                     const EquilibriumTracker& tracker) {
  std::unique_ptr<Answer> answer;
  BackgroundJob<Answer>::Failure failure;
  switch (job_.Poll(&answer, &failure)) {
    case BackgroundJob<Answer>::State::kDone:
      if (answer->generation == generation_) {
        const topology::KnotInfo& k = answer->info;
        name_ = k.ok ? k.name : "";
        constexpr int64_t kMax = std::numeric_limits<int32_t>::max();
        determinant_ = !k.ok ? 0 : (k.determinant < 0 || k.determinant > kMax)
                                       ? static_cast<int32_t>(kMax)
                                       : static_cast<int32_t>(k.determinant);
        ++identified_;
      }
      break;
    case BackgroundJob<Answer>::State::kFailed:
    case BackgroundJob<Answer>::State::kTimedOut:
      name_.clear();
      determinant_ = 0;
      break;
    case BackgroundJob<Answer>::State::kIdle:
    case BackgroundJob<Answer>::State::kRunning:
      break;
  }
  const Model& model = tracker.model();
  // The rod registers no ChainSpec (it is not re-discretised) but is a curve in space, as
  // every 3D model is; zeeman and cusp are neither.
  const bool curve = IsChain(scene.params) || model.SpatialDimension() == 3;
  if (job_.busy() || now < next_ || !curve) return;
  next_ = now + std::chrono::duration_cast<Clock::duration>(
                    std::chrono::duration<double>(1.0 / kRateHz));
  if (tracker.state().size() != model.NumStates() ||
      tracker.control().size() != model.NumControls())
    return;
  Eigen::Matrix3Xd positions;
  model.NodePositions(tracker.state(), tracker.control(), &positions);
  std::vector<Eigen::Vector3d> nodes(positions.cols());
  for (Eigen::Index k = 0; k < positions.cols(); ++k) nodes[k] = positions.col(k);
  const int64_t generation = generation_;
  job_.Start(
      [nodes = std::move(nodes), generation] {
        auto a = std::make_unique<Answer>();
        a->generation = generation;
        a->info = topology::IdentifyKnot(nodes);
        return a;
      },
      kLimit);
}

}  // namespace snapthread::server
