// Self-contact as the solvers and the tracker see it (models/contact_terms.h has the
// energy side): models whose segments are capsules that must not pass through each other
// bound every motion of the state by continuous collision detection, and report their
// active pairs. Model::contact() gives it, null for a model without self-contact (then
// every step may be taken whole and no pair is ever active).
#pragma once

#include <vector>

#include "contact/self_contact.h"
#include "numeric/types.h"

namespace snapthread {

class ContactCapability {
 public:
  virtual ~ContactCapability() = default;

  // The largest alpha in (0, 1] such that the straight step from x to x + alpha dx at
  // controls u moves no segment through another and keeps every pair's gap above a
  // tenth of its value at x (0 if two segments already touch). Every solver step is
  // scaled by it.
  virtual double MaxStepFraction(const Vec& x, const Vec& dx, const Vec& u) const = 0;
  // The same for a motion that also moves the controls (the tracker's predictor): the
  // node positions go on a straight line from those of (x0, u0) to those of (x1, u1).
  virtual double MaxMotionFraction(const Vec& x0, const Vec& u0, const Vec& x1, const Vec& u1) const = 0;
  // The active contact pairs with their closest points (status and drawing; allocates).
  virtual std::vector<contact::ContactPoint> ActiveContacts(const Vec& x, const Vec& u) const = 0;
};

}  // namespace snapthread
