#include "models/params.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "models/registry.h"

namespace snapthread {
namespace {

std::string Num(double v) {
  std::ostringstream ss;
  ss << v;
  return ss.str();
}

const ParamSpec& SpecOf(const ModelParams& p, std::string_view name) {
  const ModelRegistration* reg = FindModel(p.model);
  if (reg == nullptr) throw std::invalid_argument("model: unknown model '" + p.model + "'");
  const ParamSpec* spec = reg->FindParam(name);
  if (spec == nullptr)
    throw std::invalid_argument("params." + std::string(name) + ": " + p.model + " has no such parameter");
  return *spec;
}

double AsDouble(const ParamValue& v) {
  return std::visit([](auto x) { return static_cast<double>(x); }, v);
}

}  // namespace

std::string ParamSpec::Expected() const {
  if (kind == ParamKind::kBool) return "true or false";
  const std::string what = kind == ParamKind::kInteger ? "an integer" : "a number";
  const bool has_min = std::isfinite(min), has_max = std::isfinite(max);
  if (has_min && has_max) {
    return what + " in " + (min_inclusive ? "[" : "(") + Num(min) + ", " + Num(max) +
           (max_inclusive ? "]" : ")");
  }
  if (has_min) return what + (min_inclusive ? " >= " : " > ") + Num(min);
  if (has_max) return what + (max_inclusive ? " <= " : " < ") + Num(max);
  return what;
}

bool ParamSpec::InRange(double v) const {
  if (!std::isfinite(v)) return false;
  if (min_inclusive ? v < min : v <= min) return false;
  if (max_inclusive ? v > max : v >= max) return false;
  return true;
}

ModelParams& ModelParams::Set(std::string_view name, ParamValue value) {
  values.insert_or_assign(std::string(name), value);
  return *this;
}

double ModelParams::Number(std::string_view name) const {
  const ParamSpec& spec = SpecOf(*this, name);
  const auto it = values.find(name);
  return it == values.end() ? spec.default_value : AsDouble(it->second);
}

int ModelParams::Integer(std::string_view name) const { return static_cast<int>(std::lround(Number(name))); }

bool ModelParams::Bool(std::string_view name) const { return Number(name) != 0.0; }

bool ModelParams::IsValid(std::string* error) const {
  auto fail = [&](const std::string& m) {
    if (error) *error = m;
    return false;
  };
  const ModelRegistration* reg = FindModel(model);
  if (reg == nullptr) return fail("model: expected one of " + ModelNameList() + ", got '" + model + "'");
  for (const auto& [name, value] : values) {
    const ParamSpec* spec = reg->FindParam(name);
    const std::string key = "params." + name;
    if (spec == nullptr) return fail(key + ": " + model + " has no parameter " + name);
    switch (spec->kind) {
      case ParamKind::kBool:
        if (!std::holds_alternative<bool>(value)) return fail(key + ": expected true or false");
        break;
      case ParamKind::kInteger:
        if (!std::holds_alternative<int>(value)) return fail(key + ": expected an integer");
        break;
      case ParamKind::kNumber:
        if (std::holds_alternative<bool>(value)) return fail(key + ": expected a number");
        break;
    }
    const double v = AsDouble(value);
    if (spec->kind != ParamKind::kBool && !spec->InRange(v)) {
      if (spec->kind == ParamKind::kNumber && !std::isfinite(v))
        return fail(key + ": expected a finite number");
      return fail(key + ": expected " + spec->Expected() + ", got " + Num(v));
    }
  }
  if (reg->check && !reg->check(*this, error)) return false;
  return true;
}

}  // namespace snapthread
