#include "topology/knot_table.h"

#include <algorithm>
#include <vector>

namespace snapthread::topology {
namespace {

struct Entry {
  const char* name;
  std::vector<std::int64_t> polynomial;  // Rolfsen's table, normalised to Δ(1) = 1
};

const std::vector<Entry>& Table() {
  static const std::vector<Entry> table = {
      {"unknot", {1}},
      {"trefoil", {1, -1, 1}},
      {"figure-eight", {-1, 3, -1}},
      {"cinquefoil", {1, -1, 1, -1, 1}},
      {"three-twist", {2, -3, 2}},
      {"stevedore", {-2, 5, -2}},
      {"6_2", {-1, 3, -3, 3, -1}},
      {"6_3", {1, -3, 5, -3, 1}},
      {"granny or square", {1, -2, 3, -2, 1}},
      {"trefoil # figure-eight", {-1, 4, -5, 4, -1}},
  };
  return table;
}

}  // namespace

std::string KnotName(std::span<const std::int64_t> polynomial, std::int64_t determinant) {
  for (const Entry& e : Table()) {
    if (std::equal(polynomial.begin(), polynomial.end(), e.polynomial.begin(),
                   e.polynomial.end()))
      return e.name;
  }
  if (determinant < 0) return "unknown (det > 2^60)";
  return "unknown (det " + std::to_string(determinant) + ")";
}

}  // namespace snapthread::topology
