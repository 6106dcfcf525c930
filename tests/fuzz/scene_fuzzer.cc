// libFuzzer target: the scene loader (YAML text -> validated Scene). Any input must end in
// a Scene or a SceneError with a message; nothing else may escape, crash or hang.
// Seed corpus: tests/fuzz/corpus/scene/ (the scenes of scenes/ and bad variants).
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <exception>
#include <string>

#include "scene/scene.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const snapthread::Scene scene = snapthread::ParseScene(text, "<fuzz>");
    // A scene that loads is usable: its grasp matches its model's controls.
    if (scene.grasp_start.size() != scene.grasp_layout.NumControls()) std::abort();
  } catch (const snapthread::SceneError& e) {
    if (std::string(e.what()).empty()) std::abort();  // an error always says what is wrong
  }
  return 0;
}
