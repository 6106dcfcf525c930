#include "models/chain_model.h"

namespace snapthread::internal {

std::vector<ParamSpec> ChainParamSpecs(const std::string& bending_doc, const std::string& stretching_doc) {
  return {
      // At most 100000 segments: the reference models of the bench and advisor stay below
      // it, and a thread_shape_t carries at most 100000 nodes; n = 10^9 would allocate
      // gigabytes before failing.
      {.name = "n", .kind = ParamKind::kInteger, .default_value = 10, .min = 2, .max = 100000,
       .doc = "number of segments"},
      {.name = "segment_length", .default_value = 1.0, .min = 0.0, .min_inclusive = false,
       .units = "model length", .doc = "rest length of one segment"},
      {.name = "bending", .default_value = 1.0, .min = 0.0, .min_inclusive = false,
       .units = "model energy", .doc = bending_doc},
      {.name = "stretching", .default_value = 100.0, .min = 0.0, .min_inclusive = false,
       .units = "model energy / length^2", .doc = stretching_doc},
  };
}

}  // namespace snapthread::internal
