// Small helpers shared by the core tests.
#pragma once

#include <cstdlib>
#include <string>

#include "scene/scene.h"

namespace snapthread::testing {

inline std::string SourceDir() {
  const char* s = std::getenv("SNAPTHREAD_SOURCE_DIR");
  return s ? s : SNAPTHREAD_TEST_SOURCE_DIR;
}
inline std::string BinDir() {
  const char* s = std::getenv("SNAPTHREAD_BIN_DIR");
  return s ? s : SNAPTHREAD_TEST_BIN_DIR;
}
inline Scene SceneFile(const std::string& name, const std::vector<SceneOverride>& o = {}) {
  return LoadScene(SourceDir() + "/scenes/" + name, o);
}

}  // namespace snapthread::testing
