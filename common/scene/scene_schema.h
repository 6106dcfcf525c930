// The scene file's keys outside a model's parameters: one row per key (block, name,
// meaning, unit, default, range). The loader (scene.cc) accepts exactly these keys in
// each block; docs/scenes.md is printed from them and from each model's parameter
// schema (WriteSceneSchemaMarkdown, `snapthread-sweep --print-scene-schema`), and a test
// fails when the committed page and the printed one differ.
#pragma once

#include <ostream>
#include <set>
#include <string>
#include <string_view>
#include <vector>

namespace snapthread {

// The blocks of a scene file, as SceneKey::block names them.
inline constexpr std::string_view kSceneTop = "";                // the top level
inline constexpr std::string_view kSceneGrasp = "grasp";         // grasp: and each grasps[i]
inline constexpr std::string_view kSceneNamedGrasp = "grasps[i]";  // the keys grasps[i] adds
inline constexpr std::string_view kScenePathPoint = "path point";  // a rotation waypoint's mapping
inline constexpr std::string_view kSceneSolver = "solver";
inline constexpr std::string_view kSceneDevice = "device";
inline constexpr std::string_view kSceneTargets = "targets";

// A `targets:` block's values when the block is there but a key is not.
inline constexpr double kDefaultTargetForceError = 0.01;
inline constexpr double kDefaultTargetRateHz = 1000.0;

struct SceneKey {
  std::string block;
  std::string name;
  std::string meaning;
  std::string unit;           // "" for pure numbers, names and flags
  std::string default_value;  // "required" when there is none
  std::string range;          // what the loader accepts
};

// Every key outside params:, block by block in the order of docs/scenes.md. The defaults
// are read from SolverOptions{} and DeviceMapping{}, the structs the loader fills.
const std::vector<SceneKey>& SceneKeys();
// The names of one block's keys (what the loader's unknown-key check allows).
std::set<std::string> SceneKeyNames(std::string_view block);
// A number as the docs and messages print it (ostream's default: 1e-06, 0.08, 100).
std::string SceneNumber(double v);
// docs/scenes.md: these keys, then every registered model's parameters.
void WriteSceneSchemaMarkdown(std::ostream& out);

}  // namespace snapthread
