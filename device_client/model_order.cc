#include "model_order.h"

namespace snapthread::device {

ModelOrder::Verdict ModelOrder::Check(int64_t epoch, int64_t seq, int64_t device_seq) const {
  if (!any_) return Verdict::kNewer;
  // The pose order holds across server sessions: a new server answers poses sent after
  // the device heard of it, which are newer than every pose an old session answered.
  if (device_seq <= device_seq_) return Verdict::kOlderPose;
  // A new session numbers its models afresh (force_model_t.epoch: new at each start).
  if (epoch == epoch_ && seq <= seq_) return Verdict::kOlderSolve;
  return Verdict::kNewer;
}

void ModelOrder::Applied(int64_t epoch, int64_t seq, int64_t device_seq) {
  any_ = true;
  epoch_ = epoch;
  seq_ = seq;
  device_seq_ = device_seq;
}

}  // namespace snapthread::device
