// Model parameters: a parameter schema (one ParamSpec per parameter, declared by each
// model's registration) and ModelParams, a model name with typed values checked
// against that schema. Scene loading, --help and the tools read the schema; no code
// outside a model's own file needs to know what its parameters are called.
#pragma once

#include <limits>
#include <map>
#include <string>
#include <string_view>
#include <variant>

namespace snapthread {

enum class ParamKind { kNumber, kInteger, kBool };

// One parameter of a model: what the scene key is called, its kind, its default, the
// range it must lie in, its units and a one-line doc. Numbers must also be finite.
struct ParamSpec {
  std::string name{};
  ParamKind kind = ParamKind::kNumber;
  double default_value = 0.0;  // integers: a whole number; bools: 0 or 1
  double min = -std::numeric_limits<double>::infinity();
  bool min_inclusive = true;
  double max = std::numeric_limits<double>::infinity();
  bool max_inclusive = true;
  std::string units{};  // "model length", "" for pure numbers
  std::string doc{};    // one line, e.g. "bending stiffness β (2.1)"

  // "a number > 0", "an integer >= 2", "true or false", "a number in [0, 1)".
  std::string Expected() const;
  // `v` lies in [min, max] with the bounds' inclusiveness (and is finite).
  bool InRange(double v) const;
};

// Typed parameter values. Set(name, 10) stores an integer, Set(name, 0.5) a number,
// Set(name, true) a bool; a number parameter also accepts an integer.
using ParamValue = std::variant<bool, int, double>;

struct ModelParams {
  std::string model{};  // a registered model name (see models/registry.h)
  // The values that were set; the others take their schema default.
  std::map<std::string, ParamValue, std::less<>> values{};

  ModelParams& Set(std::string_view name, ParamValue value);
  bool Has(std::string_view name) const { return values.find(name) != values.end(); }
  // The value (or the schema default when unset) as the kind asks. Throws
  // std::invalid_argument when the model has no such parameter.
  double Number(std::string_view name) const;
  int Integer(std::string_view name) const;
  bool Bool(std::string_view name) const;

  // Ceres-style validation against the model's schema and its cross-parameter checks:
  // false and a message naming the field when invalid, e.g.
  // "params.n: expected an integer >= 2, got 1".
  bool IsValid(std::string* error) const;
};

}  // namespace snapthread
