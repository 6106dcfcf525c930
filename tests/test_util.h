// Small helpers shared by the core tests.
#pragma once

#include <string>
#include <vector>

#include "environment.h"
#include "scene/scene.h"

namespace snapthread::testing {

// The tree and the binaries: the shared test fixtures (tests/support).
using test_support::BinDir;
using test_support::SourceDir;

inline Scene SceneFile(const std::string& name, const std::vector<SceneOverride>& o = {}) {
  return LoadScene(test_support::ScenePath(name), o);
}

}  // namespace snapthread::testing
