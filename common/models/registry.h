// The model registry: a model is one source file that defines a ModelRegistration
// (name, one-line doc, parameter schema, factory, capabilities) plus one line in the
// list of registry.cc. Scene loading, --help, the tools, the server and the viewer read
// the registry; none of them spells a model name. Tests may add models at run time.
#pragma once

#include <deque>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "models/model.h"
#include "models/params.h"

namespace snapthread {

// A model that is a chain of `segments` segments of length `segment_length` (names of
// its parameters), which the bench and the advisor may re-discretise: ResizeChain keeps
// the total length n l and the continuum stiffnesses, scaling each parameter named in
// `per_length` by l_old / l_new (per-segment stiffnesses such as β, γ).
struct ChainSpec {
  std::string segments = "n";
  std::string segment_length = "segment_length";
  std::vector<std::string> per_length{};
};

struct ModelCapabilities {
  // The model's controls as a device sees them, for valid parameters.
  std::function<GraspLayout(const ModelParams&)> grasp_layout{};
  // What each grasp holds, in the order of the controls ("edge 0", "node 20"), when the
  // model has several grasps (a scene's `grasps:` names them in this order; each takes
  // grasp_layout's controls). Unset: one grasp, whatever the model's controls hold.
  std::function<std::vector<std::string>(const ModelParams&)> grasp_sites{};
  // Set for chains (see ChainSpec); their snap length scale is the segment length.
  std::optional<ChainSpec> chain{};
};

// The grasp of a planar model: (X, Y), no grip direction.
inline GraspLayout PlanarGrasp(const ModelParams&) { return GraspLayout{.spatial_dimension = 2}; }

struct ModelRegistration {
  std::string name{};
  std::string doc{};  // one line
  std::vector<ParamSpec> params{};
  // Builds the model from valid parameters (MakeModel validates first).
  std::function<std::unique_ptr<Model>(const ModelParams&)> factory{};
  // Optional checks across parameters the ranges cannot say (a grip needs n >= 3):
  // false with a message like IsValid's.
  std::function<bool(const ModelParams&, std::string*)> check{};
  ModelCapabilities capabilities{};

  const ParamSpec* FindParam(std::string_view param) const;
};

// All registered models, built-ins first in registration order.
const std::deque<ModelRegistration>& Models();
// nullptr when no model has that name.
const ModelRegistration* FindModel(std::string_view name);
// "zeeman, cusp, ..." in registration order (for "expected one of" messages and --help).
std::string ModelNameList();
// Adds a model (tests, plug-ins). Throws std::invalid_argument for an empty or taken
// name, a missing factory or grasp layout, or a default outside its range.
void RegisterModel(ModelRegistration registration);

// Validates (std::invalid_argument with IsValid's message) and builds the model.
std::unique_ptr<Model> MakeModel(const ModelParams& params);

// Capabilities of valid parameters.
GraspLayout GraspLayoutOf(const ModelParams& params);
bool IsChain(const ModelParams& params);
// The length that separates a snap from a step: the segment length of a chain, 1 model
// unit otherwise. The tracker counts a jump larger than 0.1 of it as a snap.
double SnapLengthScale(const ModelParams& params);
// Chains only (std::invalid_argument otherwise): segments and segment length.
int ChainSegments(const ModelParams& params);
double ChainSegmentLength(const ModelParams& params);
// The same parameters with n segments (segment length and stiffnesses unchanged).
ModelParams SetChainSegments(const ModelParams& params, int n);
// The same continuum chain with n segments (see ChainSpec).
ModelParams ResizeChain(const ModelParams& params, int n);

// "  zeeman     the Zeeman catastrophe machine (2.4)\n    params: ..." for --help.
std::string ModelHelp();

}  // namespace snapthread
