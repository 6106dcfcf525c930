#include "models/rod_model.h"

#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "models/contact_terms.h"
#include "models/registry.h"

namespace snapthread {

// ---------------------------------------------------------------------------------
// Registration: the scene's `model: rod`. The clamp sits at the origin with its body
// axes along the world's (the rod leaves along +x); the grasp starts with the same
// orientation, so u = (X, Y, Z, φ) with φ = 0 holds the last edge along +x and a roll
// about the tangent is φ = (roll, 0, 0).
ModelRegistration RodRegistration() {
  ModelRegistration r;
  r.name = "rod";
  r.doc = "discrete elastic rod that twists (Bergou et al. 2008/2010): full-pose clamp at the origin "
          "along +x and grasp u = (X, Y, Z, rotation vector)";
  constexpr double kInf = std::numeric_limits<double>::infinity();
  auto positive = [&](const char* name, double def, const char* units, const char* doc) {
    return ParamSpec{.name = name, .default_value = def, .min = 0.0, .min_inclusive = false,
                     .max = kInf, .units = units, .doc = doc};
  };
  r.params = {
      {.name = "n", .kind = ParamKind::kInteger, .default_value = 20, .min = 3,
       .doc = "number of edges (the clamp and the grasp hold one each)"},
      positive("length", 1.0, "m", "rest length L (every edge L / n)"),
      positive("stretch_stiffness", 1000.0, "N", "EA in 1/2 EA (|e|/l - 1)^2 l per edge"),
      positive("bend_stiffness", 1.0, "N m^2", "B1 = EI for bending towards m1 (kappa1) [DER (4)]"),
      {.name = "bend_stiffness_2", .default_value = 0.0, .min = 0.0, .units = "N m^2",
       .doc = "B2 for bending towards m2 (kappa2); 0 = bend_stiffness (a round rod), >> B1 a ribbon"},
      positive("twist_stiffness", 1.0, "N m^2", "GJ in 1/2 GJ (twist)^2 / l [DVT (4)]"),
      {.name = "natural_curvature", .default_value = 0.0, .units = "1/m",
       .doc = "natural material curvature kappa1-bar (bending towards m1)"},
      {.name = "natural_curvature_2", .default_value = 0.0, .units = "1/m",
       .doc = "natural material curvature kappa2-bar (bending towards m2)"},
      {.name = "clamp", .kind = ParamKind::kBool, .default_value = 1.0,
       .doc = "false: no clamp, a first grasp holds edge 0 (u = (its pose, the last edge's pose))"},
      {.name = "radius", .default_value = 0.01, .min = 0.0, .units = "m",
       .doc = "tube radius (drawing; the capsule radius of self-contact)"},
  };
  for (ParamSpec& spec : internal::ContactParamSpecs()) r.params.push_back(std::move(spec));
  r.factory = [](const ModelParams& mp) -> std::unique_ptr<Model> {
    RodParams p;
    p.n = mp.Integer("n");
    p.length = mp.Number("length");
    p.stretch_stiffness = mp.Number("stretch_stiffness");
    p.bend_stiffness = mp.Number("bend_stiffness");
    const double b2 = mp.Number("bend_stiffness_2");
    p.bend_stiffness_2 = b2 > 0.0 ? b2 : p.bend_stiffness;
    p.twist_stiffness = mp.Number("twist_stiffness");
    p.natural_curvature = mp.Number("natural_curvature");
    p.natural_curvature_2 = mp.Number("natural_curvature_2");
    p.radius = mp.Number("radius");
    p.free_start = !mp.Bool("clamp");
    p.contact = internal::ReadContactParams(mp);
    return std::make_unique<RodModel>(p);
  };
  r.check = [](const ModelParams& mp, std::string* error) {
    if (mp.Bool("clamp") || mp.Integer("n") >= 5) return true;
    if (error != nullptr) *error = "params.n: expected an integer >= 5 with clamp: false (two grasps)";
    return false;
  };
  r.capabilities.grasp_sites = [](const ModelParams& mp) {
    const std::string last = "edge " + std::to_string(mp.Integer("n") - 1);
    return mp.Bool("clamp") ? std::vector<std::string>{last} : std::vector<std::string>{"edge 0", last};
  };
  r.capabilities.grasp_layout = [](const ModelParams&) {
    return GraspLayout{.spatial_dimension = 3, .grip_rotation = true};
  };
  return r;
}

}  // namespace snapthread
