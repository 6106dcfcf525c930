// The order in which the device applies force models. On a lossy LAN a
// model can arrive after a newer one; rendering it would take the hand back to an older
// equilibrium (across a snap: back to the branch it just left, and forward again with
// the next model), so one snap would be felt as several force steps. A model is applied
// only when it is newer than the applied one in both orders it carries:
//  * the pose it answers (device_seq, echoed): the device's own count, strictly
//    increasing for as long as this client runs, whichever server or server run answers;
//  * the server's solve. A server that answered a late pose after a newer one sends a
//    model for a newer pose from an older state; across a snap that is the old branch.
//    Signed sessions get the solve order from auth_seq (common/auth refuses a model whose
//    auth_seq is not above the last accepted one within the server's epoch; a restarted
//    or resumed server starts a new epoch, which the device learns from its authenticated
//    status). Unsigned (in-process) sessions have no auth_seq, so the solve number `seq`
//    is used within one epoch. It is not used when signed: auth_seq already orders the
//    solves, and two counters for one order would be one more way to hold the device in
//    its fade.
// The real server solves only the newest pose and its auth_seq filter refuses a late one,
// so its models come in pose order; the rule still holds for any sender.
//
// One thread (the receiver's); no allocation.
#pragma once

#include <cstdint>

namespace snapthread::device {

class ModelOrder {
 public:
  // check_solve_seq: also require a later `seq` within an epoch (unsigned sessions).
  explicit ModelOrder(bool check_solve_seq) : check_solve_seq_(check_solve_seq) {}

  // True when the model is newer than the applied one (or is the first).
  bool IsNewer(int64_t epoch, int64_t seq, int64_t device_seq) const {
    if (!any_) return true;
    if (device_seq <= device_seq_) return false;
    return !(check_solve_seq_ && epoch == epoch_ && seq <= seq_);
  }
  // The model is now rendered: later ones must be newer than it.
  void Applied(int64_t epoch, int64_t seq, int64_t device_seq) {
    any_ = true;
    epoch_ = epoch;
    seq_ = seq;
    device_seq_ = device_seq;
  }

 private:
  bool check_solve_seq_;
  bool any_ = false;
  int64_t epoch_ = 0, seq_ = 0, device_seq_ = 0;
};

}  // namespace snapthread::device
