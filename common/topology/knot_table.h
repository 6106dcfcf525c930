// Names of the knots the Alexander polynomial tells apart (prime knots up to six
// crossings and the small composites).
#pragma once

#include <cstdint>
#include <span>
#include <string>

namespace snapthread::topology {

// The knot's name from its normalised Alexander polynomial (coefficients from t^0, Δ(1) =
// 1, no factor t) and determinant: "unknot", "trefoil", "figure-eight", "cinquefoil" (5_1),
// "three-twist" (5_2), "stevedore" (6_1), "6_2", "6_3", "granny or square" (3_1 # 3_1: the
// polynomial cannot tell them apart), "trefoil # figure-eight", or "unknown (det D)".
// A mirror image gets the same name. With no polynomial (too many crossings in the
// projection) the name is "unknown (det D)": the determinant alone does not decide.
std::string KnotName(std::span<const std::int64_t> polynomial, std::int64_t determinant);

}  // namespace snapthread::topology
