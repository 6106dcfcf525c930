#include "scene/scene.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <set>
#include <sstream>

#include <yaml-cpp/depthguard.h>
#include <yaml-cpp/yaml.h>

#include "scene/input_file.h"
#include "scene/scene_schema.h"

namespace snapthread {
namespace {

// Deepest [ ] / { } nesting a scene may have. The shipped scenes nest 3 deep; yaml-cpp
// takes seconds to scan a megabyte of open brackets before its own depth guard fires,
// so the text is checked first. Brackets inside strings count too (a bound, not a
// parse), which leaves any real scene far below the limit.
constexpr int kMaxFlowNesting = 64;

// The deepest bracket nesting of the raw text, and where it first exceeds `limit`.
int FlowNesting(const std::string& text, int limit, int* line, int* column) {
  int depth = 0, deepest = 0, l = 1, c = 0;
  for (const char ch : text) {
    ++c;
    if (ch == '\n') {
      ++l;
      c = 0;
    } else if (ch == '[' || ch == '{') {
      deepest = std::max(deepest, ++depth);
      if (depth > limit) {
        *line = l;
        *column = c;
        return depth;
      }
    } else if ((ch == ']' || ch == '}') && depth > 0) {
      --depth;
    }
  }
  return deepest;
}

class Reader {
 public:
  explicit Reader(std::string file) : file_(std::move(file)) {}

  [[noreturn]] void Fail(const std::string& key, const std::string& what) const {
    throw SceneError(file_ + ": " + key + ": " + what);
  }

  template <class T>
  T Get(const YAML::Node& node, const std::string& key, const char* expected) const {
    try {
      return node.as<T>();
    } catch (const YAML::Exception&) {
      Fail(key, std::string("expected ") + expected + ", got '" + Dump(node) + "'");
    }
  }
  double Number(const YAML::Node& parent, const std::string& name, const std::string& key,
                double fallback, bool required = false) const {
    const YAML::Node n = parent[name];
    if (!n) {
      if (required) Fail(key, "missing (expected a number)");
      return fallback;
    }
    const double v = Get<double>(n, key, "a number");
    if (!std::isfinite(v)) Fail(key, "expected a finite number");
    return v;
  }
  double Positive(const YAML::Node& parent, const std::string& name, const std::string& key,
                  double fallback, bool required = false) const {
    const double v = Number(parent, name, key, fallback, required);
    if (!(v > 0.0)) Fail(key, "expected a number > 0, got " + Num(v));
    return v;
  }
  Vec Vector(const YAML::Node& n, const std::string& key, int size) const {
    if (!n.IsSequence() || static_cast<int>(n.size()) != size)
      Fail(key, "expected a list of " + std::to_string(size) + " numbers, got '" + Dump(n) + "'");
    Vec v(size);
    for (int i = 0; i < size; ++i) {
      v[i] = Get<double>(n[i], key, "a number");
      if (!std::isfinite(v[i])) Fail(key, "expected finite numbers");
    }
    return v;
  }
  void CheckKeys(const YAML::Node& n, const std::string& key, std::set<std::string> allowed) const {
    if (!n.IsMap()) Fail(key, "expected a mapping, got '" + Dump(n) + "'");
    std::set<std::string> seen;
    for (const auto& kv : n) {
      if (!kv.first.IsScalar()) {
        Fail(key.empty() ? "top level" : key, "expected plain names as keys, got '" + Dump(kv.first) + "'");
      }
      const std::string k = kv.first.as<std::string>();
      // yaml-cpp keeps both entries of a repeated key and lookups see the first: refuse
      // it rather than silently ignore one of the two values.
      if (!seen.insert(k).second) Fail(key.empty() ? k : key + "." + k, "duplicated key");
      if (!allowed.count(k)) {
        std::string list;
        for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
        Fail(key.empty() ? k : key + "." + k, "unknown key (expected one of: " + list + ")");
      }
    }
  }
  static std::string Dump(const YAML::Node& n) {
    std::stringstream ss;
    ss << n;
    std::string s = ss.str();
    for (char& c : s)
      if (c == '\n') c = ' ';
    return s.size() > 60 ? s.substr(0, 57) + "..." : s;
  }
  static std::string Num(double v) {
    std::ostringstream ss;
    ss << v;
    return ss.str();
  }

 private:
  std::string file_;
};

// The model's parameters, as its schema says: kinds, ranges, allowed keys.
void ReadParams(const YAML::Node& p, const ModelRegistration& model, const Reader& rd, ModelParams* params) {
  if (model.params.empty()) {
    if (!p.IsMap() && !p.IsNull()) rd.Fail("params", "expected a mapping, got '" + Reader::Dump(p) + "'");
    if (p.size() > 0) rd.Fail("params", model.name + " takes no parameters");
    return;
  }
  std::set<std::string> allowed;
  for (const ParamSpec& spec : model.params) allowed.insert(spec.name);
  rd.CheckKeys(p, "params", allowed);
  for (const ParamSpec& spec : model.params) {
    const YAML::Node v = p[spec.name];
    if (!v) continue;
    const std::string key = "params." + spec.name;
    switch (spec.kind) {
      case ParamKind::kBool:
        params->Set(spec.name, rd.Get<bool>(v, key, "true or false"));
        continue;
      case ParamKind::kInteger: {
        const int n = rd.Get<int>(v, key, "an integer");
        if (!spec.InRange(n)) rd.Fail(key, "expected " + spec.Expected() + ", got " + std::to_string(n));
        params->Set(spec.name, n);
        continue;
      }
      case ParamKind::kNumber: {
        const double x = rd.Number(p, spec.name, key, spec.default_value);
        if (!spec.InRange(x)) rd.Fail(key, "expected " + spec.Expected() + ", got " + Reader::Num(x));
        params->Set(spec.name, x);
        continue;
      }
    }
  }
}

// A waypoint of a grasp that holds its full orientation (GraspLayout::grip_rotation):
// [X, Y, Z] (start orientation), or {position: [X, Y, Z], roll_deg: r}, a roll by r
// degrees about the grasp's x axis, the rod's tangent at the start (u = (X, Y, Z, r, 0, 0)
// in radians), or {position: [X, Y, Z], rotation_deg: [a, b, c]}, the rotation vector φ
// in degrees (a hand that turns the rod's end about any axis). Legs between waypoints
// interpolate the rotation vector linearly, so a leg from roll 0 to roll 720 turns the
// grasp twice.
Vec RotationWaypoint(const YAML::Node& point, const std::string& key, const Reader& rd) {
  Vec p = Vec::Zero(6);
  if (point.IsSequence()) {
    p.head(3) = rd.Vector(point, key, 3);
    return p;
  }
  if (!point.IsMap()) rd.Fail(key, "expected [X, Y, Z] or {position: [X, Y, Z], roll_deg: r}, got '" + Reader::Dump(point) + "'");
  rd.CheckKeys(point, key, SceneKeyNames(kScenePathPoint));
  if (!point["position"]) rd.Fail(key + ".position", "missing (expected a list of 3 numbers)");
  if (point["roll_deg"] && point["rotation_deg"]) rd.Fail(key + ".rotation_deg", "also given as roll_deg; keep one");
  p.head(3) = rd.Vector(point["position"], key + ".position", 3);
  constexpr double kRad = std::numbers::pi / 180.0;
  p[3] = rd.Number(point, "roll_deg", key + ".roll_deg", 0.0) * kRad;
  if (point["rotation_deg"]) p.tail(3) = rd.Vector(point["rotation_deg"], key + ".rotation_deg", 3) * kRad;
  return p;
}

struct GraspRead {
  Vec start;
  std::vector<Vec> path;
};

// One grasp's start and path: the position (2 or 3 numbers), then a unit grip direction
// if the model holds one, or a rotation vector (start: 0) if it holds the full
// orientation (see GraspLayout). `extra` are further keys the caller reads.
GraspRead ReadGrasp(const YAML::Node& g, const std::string& key, const GraspLayout& layout,
                    const Reader& rd, std::set<std::string> extra = {}) {
  const int pos_dim = layout.spatial_dimension;
  const bool grip = layout.grip_direction;
  const int m = layout.NumControls();
  for (const std::string& k : SceneKeyNames(kSceneGrasp)) extra.insert(k);
  rd.CheckKeys(g, key, extra);
  if (!g["start"]) rd.Fail(key + ".start", "missing (expected a list of " + std::to_string(pos_dim) + " numbers)");
  Vec start = rd.Vector(g["start"], key + ".start", pos_dim);
  Vec dir;
  if (grip) {
    if (!g["direction"]) rd.Fail(key + ".direction", "missing: params.grip_direction needs a list of 3 numbers");
    dir = rd.Vector(g["direction"], key + ".direction", 3);
    if (!(dir.norm() > 1e-9)) rd.Fail(key + ".direction", "expected a non-zero vector");
    dir.normalize();
  } else if (g["direction"]) {
    rd.Fail(key + ".direction", "only allowed with params.grip_direction: true");
  }
  GraspRead out;
  out.start = Vec::Zero(m);
  out.start.head(pos_dim) = start;
  if (grip) out.start.tail(3) = dir;
  if (g["path"]) {
    const YAML::Node path = g["path"];
    if (!path.IsSequence() || path.size() < 1) rd.Fail(key + ".path", "expected a list of points");
    for (size_t i = 0; i < path.size(); ++i) {
      const std::string pkey = key + ".path[" + std::to_string(i) + "]";
      Vec p(m);
      // With a grip direction a waypoint may also turn the grip: X,Y,Z,dx,dy,dz.
      if (layout.grip_rotation) {
        p = RotationWaypoint(path[i], pkey, rd);
      } else if (grip && path[i].IsSequence() && path[i].size() == 6) {
        p = rd.Vector(path[i], pkey, 6);
        if (!(p.tail(3).norm() > 1e-9)) rd.Fail(pkey, "expected a non-zero grip direction");
        p.tail(3).normalize();
      } else {
        p.head(pos_dim) = rd.Vector(path[i], pkey, pos_dim);
        if (grip) p.tail(3) = dir;
      }
      out.path.push_back(p);
    }
  }
  return out;
}

// `grasps:`: a list of {name, edge | node, start, path, ...}, one per grasp site of the
// model, in the model's order. Paths: every grasp with a path gives the same number of
// points; a grasp without one holds its start. u and the path points concatenate them.
void ReadGrasps(const YAML::Node& list, const ModelRegistration& model, const Reader& rd, Scene* sc) {
  const std::vector<std::string> sites =
      model.capabilities.grasp_sites ? model.capabilities.grasp_sites(sc->params) : std::vector<std::string>{};
  if (!list.IsSequence() || list.size() < 1) rd.Fail("grasps", "expected a list of grasps");
  if (sites.empty() && list.size() != 1) rd.Fail("grasps", sc->params.model + " has one grasp");
  if (!sites.empty() && list.size() != sites.size())
    rd.Fail("grasps", "expected " + std::to_string(sites.size()) + " grasps (holding " + [&] {
      std::string all;
      for (const auto& s : sites) all += (all.empty() ? "" : ", ") + s;
      return all;
    }() + ")");
  const int m = sc->grasp_layout.NumControls();
  std::vector<GraspRead> reads;
  size_t path_points = 0;
  for (size_t i = 0; i < list.size(); ++i) {
    const std::string key = "grasps[" + std::to_string(i) + "]";
    const YAML::Node g = list[i];
    if (!g.IsMap()) rd.Fail(key, "expected a mapping with name, edge or node, start, path");
    GraspRead r = ReadGrasp(g, key, sc->grasp_layout, rd, SceneKeyNames(kSceneNamedGrasp));
    SceneGrasp sg;
    if (!g["name"]) rd.Fail(key + ".name", "missing (expected a name, e.g. left)");
    sg.name = rd.Get<std::string>(g["name"], key + ".name", "a name");
    if (sg.name.empty() || sg.name.find_first_of(" ,\t\n") != std::string::npos)
      rd.Fail(key + ".name", "expected a name without spaces or commas");
    for (const SceneGrasp& other : sc->grasps)
      if (other.name == sg.name) rd.Fail(key + ".name", "duplicated grasp name '" + sg.name + "'");
    if (g["edge"] && g["node"]) rd.Fail(key, "give edge or node, not both");
    if (!g["edge"] && !g["node"]) rd.Fail(key + ".edge", "missing (expected the edge or node the grasp holds)");
    const char* kind = g["edge"] ? "edge" : "node";
    int index = rd.Get<int>(g[kind], key + "." + kind, "an integer");
    // A negative index counts from the end (-1: the last edge or node of a model with
    // params.n edges), so a scene's grasps follow `--set params.n=...`.
    if (index < 0 && sc->params.Has("n")) {
      const int count = sc->params.Integer("n") + (std::string(kind) == "node" ? 1 : 0);
      if (index < -count)
        rd.Fail(key + "." + kind, std::to_string(index) + " counts from the end past the first of " +
                                      std::to_string(count) + " " + kind + "s");
      index += count;
    }
    sg.holds = std::string(kind) + " " + std::to_string(index);
    const std::string expected = sites.empty() ? sg.holds : sites[i];
    if (sg.holds != expected)
      rd.Fail(key + "." + kind, "expected the " + expected + " (the model's grasps in order), got " + sg.holds);
    sg.offset = static_cast<int>(i) * m;
    if (g["model_origin"]) {
      const Vec o = rd.Vector(g["model_origin"], key + ".model_origin", 3);
      sg.has_model_origin = true;
      sg.model_origin = {o[0], o[1], o[2]};
    }
    if (!r.path.empty()) {
      if (path_points != 0 && r.path.size() != path_points)
        rd.Fail(key + ".path", "expected " + std::to_string(path_points) + " points as the other grasps' paths");
      path_points = r.path.size();
    }
    sc->grasps.push_back(sg);
    reads.push_back(std::move(r));
  }
  const int total = m * static_cast<int>(reads.size());
  sc->grasp_start.resize(total);
  for (size_t i = 0; i < reads.size(); ++i) sc->grasp_start.segment(i * m, m) = reads[i].start;
  for (size_t k = 0; k < path_points; ++k) {
    Vec p(total);
    for (size_t i = 0; i < reads.size(); ++i)
      p.segment(i * m, m) = reads[i].path.empty() ? reads[i].start : reads[i].path[k];
    sc->path.push_back(p);
  }
}

void ApplyOverrides(YAML::Node root, const std::vector<SceneOverride>& overrides, const Reader& rd) {
  for (const auto& o : overrides) {
    YAML::Node value;
    try {
      value = YAML::Load(o.value);
    } catch (const YAML::Exception& e) {
      rd.Fail(o.key, "override value '" + o.value + "' is not valid YAML");
    }
    std::vector<std::string> parts;
    std::stringstream ss(o.key);
    for (std::string p; std::getline(ss, p, '.');) {
      if (p.empty()) rd.Fail(o.key, "malformed override key");
      parts.push_back(p);
    }
    if (parts.empty()) rd.Fail(o.key, "malformed override key");
    // yaml-cpp nodes are handles: walk with fresh handles via reset().
    std::vector<YAML::Node> chain{root};
    for (size_t i = 0; i + 1 < parts.size(); ++i) {
      YAML::Node child = chain.back()[parts[i]];
      if (!child || !child.IsMap()) {
        chain.back()[parts[i]] = YAML::Node(YAML::NodeType::Map);
        child = chain.back()[parts[i]];
      }
      chain.push_back(child);
    }
    chain.back()[parts.back()] = value;
  }
}

// solver.start_continuation: a list of the model's number parameters whose range holds 0
// (the start solve continues them from 0 to the scene's values).
void ReadStartContinuation(const YAML::Node& list, const ModelRegistration& model, const Reader& rd, Scene* sc) {
  const std::string key = "solver.start_continuation";
  if (!list.IsSequence()) rd.Fail(key, "expected a list of parameter names, got '" + Reader::Dump(list) + "'");
  for (const auto& item : list) {
    const std::string name = rd.Get<std::string>(item, key, "a parameter name");
    const ParamSpec* spec = model.FindParam(name);
    if (spec == nullptr || spec->kind != ParamKind::kNumber || !spec->InRange(0.0))
      rd.Fail(key, "expected number parameters of " + model.name + " that may be 0, got '" + name + "'");
    if (std::find(sc->start_continuation.begin(), sc->start_continuation.end(), name) !=
        sc->start_continuation.end())
      rd.Fail(key, "'" + name + "' listed twice");
    sc->start_continuation.push_back(name);
  }
}

// The scene's solver: block (what it says about solving; the method is checked where the
// solver is made).
void ReadSolver(const YAML::Node& s, const ModelRegistration& model, const Reader& rd, Scene* sc) {
  rd.CheckKeys(s, "solver", SceneKeyNames(kSceneSolver));
  if (s["start_continuation"]) ReadStartContinuation(s["start_continuation"], model, rd, sc);
  sc->max_update_hz = rd.Number(s, "max_update_hz", "solver.max_update_hz", 0.0);
  if (!(sc->max_update_hz >= 0.0 && sc->max_update_hz <= 100000.0))
    throw SceneError(sc->file + ": solver.max_update_hz: expected a rate in [0, 100000] Hz (0 = no cap), got " +
                     std::to_string(sc->max_update_hz));
  if (s["method"]) {
    // A registered solver's name: checked where the solver is made (MakeSolver), since
    // a scene links no solver code (the device client reads scenes).
    sc->solver.method = rd.Get<std::string>(s["method"], "solver.method", "a method name");
  }
  sc->solver.cutoff = rd.Positive(s, "cutoff", "solver.cutoff", sc->solver.cutoff);
  sc->solver.force_tolerance = rd.Number(s, "force_tolerance", "solver.force_tolerance", sc->solver.force_tolerance);
  sc->solver.force_floor_n = rd.Number(s, "force_floor_n", "solver.force_floor_n", sc->solver.force_floor_n);
  if (s["max_iterations"]) {
    sc->solver.max_iterations = rd.Get<int>(s["max_iterations"], "solver.max_iterations", "an integer >= 0");
  }
  // time_budget_us; max_time_us is its earlier spelling, still read.
  if (s["time_budget_us"] && s["max_time_us"])
    throw SceneError(sc->file + ": solver.time_budget_us: also given as solver.max_time_us; keep one");
  sc->solver.max_time_us = s["time_budget_us"]
                              ? rd.Number(s, "time_budget_us", "solver.time_budget_us", 0.0)
                              : rd.Number(s, "max_time_us", "solver.max_time_us", 0.0);
  if (s["linear_solver"])
    sc->solver.linear_solver = rd.Get<std::string>(s["linear_solver"], "solver.linear_solver", "a backend name");
  sc->solver.degeneracy_ratio = rd.Number(s, "degeneracy_ratio", "solver.degeneracy_ratio", sc->solver.degeneracy_ratio);
  sc->solver.max_reduction_step =
      rd.Number(s, "max_reduction_step", "solver.max_reduction_step", sc->solver.max_reduction_step);
  if (s["secant_predictor"])
    sc->solver.secant_predictor = rd.Get<bool>(s["secant_predictor"], "solver.secant_predictor", "true or false");
  std::string error;
  if (!sc->solver.IsValid(&error)) throw SceneError(sc->file + ": " + error);
}

// The scene's device: block (the map between the model and the haptic device).
void ReadDevice(const YAML::Node& d, const Reader& rd, DeviceMapping* device) {
  rd.CheckKeys(d, "device", SceneKeyNames(kSceneDevice));
  DeviceMapping& dm = *device;
  dm.model_units_per_metre = rd.Positive(d, "model_units_per_metre", "device.model_units_per_metre", dm.model_units_per_metre);
  dm.newtons_per_model_force =
      rd.Positive(d, "newtons_per_model_force", "device.newtons_per_model_force", dm.newtons_per_model_force);
  dm.max_force_n = rd.Positive(d, "max_force_n", "device.max_force_n", dm.max_force_n);
  dm.max_stiffness_n_per_m = rd.Positive(d, "max_stiffness_n_per_m", "device.max_stiffness_n_per_m", dm.max_stiffness_n_per_m);
  dm.workspace_radius_m = rd.Positive(d, "workspace_radius_m", "device.workspace_radius_m", dm.workspace_radius_m);
  if (d["model_origin"]) {
    const Vec o = rd.Vector(d["model_origin"], "device.model_origin", 3);
    dm.model_origin = {o[0], o[1], o[2]};
  }
}

}  // namespace

SceneOverride ParseOverride(const std::string& text) {
  const auto eq = text.find('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 == text.size())
    throw SceneError("--set '" + text + "': expected key=value, e.g. params.n=20");
  return {text.substr(0, eq), text.substr(eq + 1)};
}

Scene ParseScene(const std::string& yaml_text, const std::string& file_label,
                 const std::vector<SceneOverride>& overrides) {
  Reader rd(file_label);
  int line = 0, column = 0;
  if (FlowNesting(yaml_text, kMaxFlowNesting, &line, &column) > kMaxFlowNesting) {
    throw SceneError(file_label + ": brackets nested deeper than " + std::to_string(kMaxFlowNesting) +
                     " levels at line " + std::to_string(line) + ", column " + std::to_string(column) +
                     " (not a scene)");
  }
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::DeepRecursion& e) {
    throw SceneError(file_label + ": nested deeper than " + std::to_string(e.depth()) + " levels at line " +
                     std::to_string(e.mark.line + 1) + ", column " + std::to_string(e.mark.column + 1) +
                     " (not a scene)");
  } catch (const YAML::Exception& e) {
    throw SceneError(file_label + ": not valid YAML: " + e.what());
  }
  if (!root || !root.IsMap()) throw SceneError(file_label + ": expected a YAML mapping at the top level");
  ApplyOverrides(root, overrides, rd);
  rd.CheckKeys(root, "", SceneKeyNames(kSceneTop));

  Scene sc;
  sc.file = file_label;
  if (!root["model"]) rd.Fail("model", "missing (expected one of " + ModelNameList() + ")");
  sc.params.model = rd.Get<std::string>(root["model"], "model", "a model name");
  const ModelRegistration* model = FindModel(sc.params.model);
  if (model == nullptr)
    rd.Fail("model", "expected one of " + ModelNameList() + ", got '" + sc.params.model + "'");
  sc.name = root["name"] ? rd.Get<std::string>(root["name"], "name", "a string") : sc.params.model;
  if (root["description"]) sc.description = rd.Get<std::string>(root["description"], "description", "a string");

  if (root["params"]) {
    ReadParams(root["params"], *model, rd, &sc.params);
  } else if (!model->params.empty()) {
    std::string names;
    for (const ParamSpec& spec : model->params) names += (names.empty() ? "" : ", ") + spec.name;
    rd.Fail("params", "missing (expected " + names + ")");
  }
  std::string error;
  if (!sc.params.IsValid(&error)) throw SceneError(file_label + ": " + error);

  sc.grasp_layout = model->capabilities.grasp_layout(sc.params);
  if (root["grasp"] && root["grasps"]) rd.Fail("grasps", "also given as grasp; keep one");
  if (root["grasps"]) {
    ReadGrasps(root["grasps"], *model, rd, &sc);
  } else {
    if (!root["grasp"]) rd.Fail("grasp", "missing (expected start and path)");
    if (model->capabilities.grasp_sites && model->capabilities.grasp_sites(sc.params).size() != 1)
      rd.Fail("grasp", "this model has several grasps: name them under grasps:");
    GraspRead g = ReadGrasp(root["grasp"], "grasp", sc.grasp_layout, rd);
    sc.grasps = {SceneGrasp{}};
    sc.grasp_start = std::move(g.start);
    sc.path = std::move(g.path);
  }

  if (root["solver"]) ReadSolver(root["solver"], *model, rd, &sc);
  if (root["device"]) ReadDevice(root["device"], rd, &sc.device);
  if (root["targets"]) {
    const YAML::Node t = root["targets"];
    rd.CheckKeys(t, "targets", SceneKeyNames(kSceneTargets));
    sc.target_force_error = rd.Positive(t, "force_error", "targets.force_error", kDefaultTargetForceError);
    sc.target_rate_hz = rd.Positive(t, "rate_hz", "targets.rate_hz", kDefaultTargetRateHz);
  }
  return sc;
}

int FindGrasp(const Scene& scene, const std::string& name) {
  if (name.empty()) return 0;
  for (size_t i = 0; i < scene.grasps.size(); ++i)
    if (scene.grasps[i].name == name) return static_cast<int>(i);
  return -1;
}

DeviceMapping GraspDeviceMapping(const Scene& scene, int grasp) {
  DeviceMapping m = scene.device;
  if (grasp >= 0 && grasp < static_cast<int>(scene.grasps.size()) && scene.grasps[grasp].has_model_origin)
    m.model_origin = scene.grasps[grasp].model_origin;
  return m;
}

Scene LoadScene(const std::string& path, const std::vector<SceneOverride>& overrides) {
  std::string text;
  try {
    text = ReadInputFile(path, kMaxSceneFileBytes, "scene file");
  } catch (const InputFileError& e) {
    throw SceneError(e.what());
  }
  return ParseScene(text, path, overrides);
}

}  // namespace snapthread
