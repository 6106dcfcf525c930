// The order in which the device applies force models (issue 12 item 4). On a lossy LAN a
// model can arrive after a newer one; rendering it would take the hand back to an older
// equilibrium (across a snap: back to the branch it just left, and forward again with
// the next model), so one snap would be felt as several force steps. A model is applied
// only when it is newer than the last applied one in both of the orders it carries:
//  * the pose it answers (device_seq): the device's own count, strictly increasing for
//    as long as this client runs, whichever server answers;
//  * the server's solve (seq, "increments by one per published model"), within one
//    server session (epoch): a server that answered a late pose after a newer one sends
//    an older-pose model with a newer seq, and the reverse order is refused by seq.
// Authentication (auth_seq, common/auth) already refuses reordered signed models; this
// gate states the rule on the model's own fields, so it also holds for unsigned
// in-process sessions and whatever order the signing and the solving happened in.
//
// One thread (the receiver's); no allocation.
#pragma once

#include <cstdint>

namespace snapthread::device {

class ModelOrder {
 public:
  enum class Verdict : uint8_t {
    kNewer,       // apply it
    kOlderPose,   // answers a pose no newer than the applied model's
    kOlderSolve,  // same server session, solved no later than the applied model
  };

  // What Applied would make of this model, changing nothing.
  Verdict Check(int64_t epoch, int64_t seq, int64_t device_seq) const;
  // The model now rendered: later ones must be newer than it.
  void Applied(int64_t epoch, int64_t seq, int64_t device_seq);

 private:
  bool any_ = false;
  int64_t epoch_ = 0;
  int64_t seq_ = 0;
  int64_t device_seq_ = 0;
};

}  // namespace snapthread::device
