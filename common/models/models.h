// Model parameters and the factory for the seed's four systems.
#pragma once

#include <memory>
#include <string>

#include "models/model.h"

namespace snapthread {

struct ModelParams {
  std::string model;            // "zeeman" | "cusp" | "curve2d" | "thread3d"
  int n = 10;                   // segments (curve2d, thread3d); >= 2 (>= 3 with a grip direction)
  double segment_length = 1.0;  // l_i (curve2d) / L_i (thread3d), model length units
  double bending = 1.0;         // beta  (curve2d: beta (1 - t.t); thread3d: beta/2 (b_i - B_i))
  double stretching = 100.0;    // gamma (curve2d: gamma (|v|-l)^2; thread3d: gamma/2 (l-L)^2)
  double reference_bend = 0.0;  // B_i (thread3d (3.9)); shifts the energy only
  // thread3d only: the grip constrains the last segment's direction. Then the controls
  // are u = (X, Y, Z, dx, dy, dz) and node N-1 = p_N - s d/|d| with s free (3.15 + grip).
  bool grip_direction = false;

  // Ceres-style validation: false and a message naming the field when invalid.
  bool IsValid(std::string* error) const;
};

// Throws std::invalid_argument (with IsValid's message) for invalid parameters.
std::unique_ptr<Model> MakeModel(const ModelParams& params);

// Individual constructors (same validation).
std::unique_ptr<Model> MakeZeemanModel();
std::unique_ptr<Model> MakeCuspModel();
std::unique_ptr<Model> MakeCurve2dModel(const ModelParams& params);
std::unique_ptr<Model> MakeThread3dModel(const ModelParams& params);

}  // namespace snapthread
