#include "models/registry.h"

#include <cmath>
#include <deque>
#include <mutex>
#include <sstream>
#include <stdexcept>

namespace snapthread {

// The built-in models, one line each: <Name> names the function
// `ModelRegistration <Name>Registration()` that the model's own source file defines.
// No static-initialisation tricks: with static libraries those registrations would be
// dropped by the linker; this explicit list is the one registration of a model.
#define SNAPTHREAD_BUILTIN_MODELS(X) \
  X(Zeeman)                          \
  X(Cusp)                            \
  X(Curve2d)                         \
  X(Thread3d)                        \
  X(Rod)

#define SNAPTHREAD_DECLARE_MODEL(Name) ModelRegistration Name##Registration();
SNAPTHREAD_BUILTIN_MODELS(SNAPTHREAD_DECLARE_MODEL)
#undef SNAPTHREAD_DECLARE_MODEL

namespace {

void Check(const ModelRegistration& r) {
  if (r.name.empty()) throw std::invalid_argument("RegisterModel: empty model name");
  if (!r.factory) throw std::invalid_argument("RegisterModel: " + r.name + " has no factory");
  if (!r.capabilities.grasp_layout)
    throw std::invalid_argument("RegisterModel: " + r.name + " has no grasp layout");
  for (const ParamSpec& p : r.params) {
    if (!p.InRange(p.default_value) && p.kind != ParamKind::kBool)
      throw std::invalid_argument("RegisterModel: " + r.name + "." + p.name + ": default outside " + p.Expected());
  }
  if (r.capabilities.chain) {
    const ChainSpec& c = *r.capabilities.chain;
    if (!r.FindParam(c.segments) || !r.FindParam(c.segment_length))
      throw std::invalid_argument("RegisterModel: " + r.name + ": the chain names unknown parameters");
  }
}

// Built once on first use; RegisterModel appends. A deque, so the pointers FindModel
// hands out stay valid when a test registers a model later.
std::deque<ModelRegistration>& Registry() {
  static std::deque<ModelRegistration> registry = [] {
    std::deque<ModelRegistration> r;
#define SNAPTHREAD_ADD_MODEL(Name) r.push_back(Name##Registration());
    SNAPTHREAD_BUILTIN_MODELS(SNAPTHREAD_ADD_MODEL)
#undef SNAPTHREAD_ADD_MODEL
    for (const ModelRegistration& m : r) Check(m);
    return r;
  }();
  return registry;
}

std::mutex& RegistryMutex() {
  static std::mutex m;
  return m;
}

const ChainSpec& ChainOf(const ModelParams& params) {
  const ModelRegistration* reg = FindModel(params.model);
  if (reg == nullptr || !reg->capabilities.chain)
    throw std::invalid_argument("model " + params.model + " is not a chain");
  return *reg->capabilities.chain;
}

}  // namespace

const ParamSpec* ModelRegistration::FindParam(std::string_view param) const {
  for (const ParamSpec& p : params) {
    if (p.name == param) return &p;
  }
  return nullptr;
}

const std::deque<ModelRegistration>& Models() { return Registry(); }

const ModelRegistration* FindModel(std::string_view name) {
  std::lock_guard<std::mutex> lock(RegistryMutex());
  for (const ModelRegistration& m : Registry()) {
    if (m.name == name) return &m;
  }
  return nullptr;
}

std::string ModelNameList() {
  std::string list;
  for (const ModelRegistration& m : Models()) list += (list.empty() ? "" : ", ") + m.name;
  return list;
}

void RegisterModel(ModelRegistration registration) {
  Check(registration);
  if (FindModel(registration.name) != nullptr)
    throw std::invalid_argument("RegisterModel: a model named " + registration.name + " already exists");
  std::lock_guard<std::mutex> lock(RegistryMutex());
  Registry().push_back(std::move(registration));
}

std::unique_ptr<Model> MakeModel(const ModelParams& params) {
  std::string error;
  if (!params.IsValid(&error)) throw std::invalid_argument(error);
  return FindModel(params.model)->factory(params);
}

GraspLayout GraspLayoutOf(const ModelParams& params) {
  const ModelRegistration* reg = FindModel(params.model);
  if (reg == nullptr) throw std::invalid_argument("model: unknown model '" + params.model + "'");
  return reg->capabilities.grasp_layout(params);
}

bool IsChain(const ModelParams& params) {
  const ModelRegistration* reg = FindModel(params.model);
  return reg != nullptr && reg->capabilities.chain.has_value();
}

double SnapLengthScale(const ModelParams& params) { return IsChain(params) ? ChainSegmentLength(params) : 1.0; }

int ChainSegments(const ModelParams& params) { return params.Integer(ChainOf(params).segments); }

double ChainSegmentLength(const ModelParams& params) { return params.Number(ChainOf(params).segment_length); }

ModelParams SetChainSegments(const ModelParams& params, int n) {
  ModelParams p = params;
  p.Set(ChainOf(params).segments, n);
  return p;
}

ModelParams ResizeChain(const ModelParams& params, int n) {
  const ChainSpec& chain = ChainOf(params);
  const double l_old = ChainSegmentLength(params);
  const double l_new = ChainSegments(params) * l_old / n;
  ModelParams p = params;
  p.Set(chain.segments, n);
  p.Set(chain.segment_length, l_new);
  // A continuum thread has fixed EI and EA: the per-segment β ~ EI / l and γ ~ EA / l.
  for (const std::string& name : chain.per_length) p.Set(name, params.Number(name) * l_old / l_new);
  return p;
}

std::string ModelHelp() {
  std::ostringstream out;
  for (const ModelRegistration& m : Models()) {
    out << "  " << m.name << ": " << m.doc << "\n";
    for (const ParamSpec& p : m.params) {
      out << "      params." << p.name << " (" << p.Expected();
      if (!p.units.empty()) out << ", " << p.units;
      out << ", default ";
      if (p.kind == ParamKind::kBool) {
        out << (p.default_value != 0.0 ? "true" : "false");
      } else {
        out << p.default_value;
      }
      out << "): " << p.doc << "\n";
    }
  }
  return out.str();
}

}  // namespace snapthread
