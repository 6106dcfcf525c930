// The envelope one rendered vector (the force, or the grip torque) goes through each servo
// tick, after the local model and its fade (safety.h), in this order: a non-finite v aims
// at zero (counted as a clamp: no direction to keep); |v| <= max_norm; |v - last| <=
// max_step (the slew limit per tick); a non-finite result (which the steps above cannot
// make from a finite last) is zeroed. One limiter per rendered vector, holding its last
// output; fixed size, no allocation, no locks (the servo tick calls it).
#pragma once

namespace snapthread::device {

// What one Apply did.
struct LimitVerdict {
  bool clamped = false;       // the norm limit acted (or v was non-finite)
  bool slew_limited = false;  // the slew limit acted
  bool nonfinite = false;     // the result was zeroed: must never happen
};

class VectorLimiter {
 public:
  // max_norm: the bound on |v|; max_step: the bound on |v - last| per tick (a rate times
  // the tick period). The last output starts at zero.
  VectorLimiter(double max_norm, double max_step) : max_norm_(max_norm), max_step_(max_step) {}

  // Limits v in place; the last output becomes it.
  LimitVerdict Apply(double v[3]);

  const double* last() const { return last_; }

 private:
  double max_norm_;
  double max_step_;
  double last_[3] = {0.0, 0.0, 0.0};
};

}  // namespace snapthread::device
