// The stiffness clamps of the device's local model (shared/DESIGN.md "Forces and the
// device's local model"), applied off the servo thread when a force model arrives
// (PrepareModel, local_model.h) so the servo tick only evaluates a model that a haptic
// loop can render stably.
//
// Sign convention: K = dF/du (force_model_t), so a passive spring has K negative
// semi-definite. The *stiffness* S = -sym(K) is what a haptic loop can render stably
// only when 0 <= S <= max_stiffness: S < 0 (energy-releasing, F pushing the hand further
// out) and S above the device's stable stiffness are what make a haptic loop unstable.
#pragma once

#include <string>

#include "safety_limits.h"

namespace snapthread::device {

// K (dF/du, N/m) with the stiffness S = -sym(K) clamped to [0, max stable stiffness] into
// out (finite); *clamped when a clamp acted. False (with *why) when it cannot be done.
bool ClampStiffness(const double K[3][3], const SafetyLimits& limits, double out[3][3],
                    bool* clamped, std::string* why);

// K6 (force_model_t, rows F then τ, columns metres then radians) made safe for a haptic
// loop, into out (finite): in the coordinates (u, ℓ r), ℓ² = max_torque_stiffness /
// max_stiffness, where both stiffness bounds are the one max_stiffness, the stiffness
// -sym(K6') has its eigenvalues clamped to [0, max_stiffness] (the force block, the torque
// block and their coupling together: a 6-DoF spring that releases no energy and is not
// stiffer than the device), and the antisymmetric part (-½[τ0]× of a left-trivialised
// torque) is bounded by |τ| <= max_torque. *clamped when a clamp acted. With either
// stiffness bound 0 only the force block is kept (clamped as ClampStiffness does).
bool ClampWrenchStiffness(const double K6[6][6], const SafetyLimits& limits, double out[6][6],
                          bool* clamped, std::string* why);

}  // namespace snapthread::device
