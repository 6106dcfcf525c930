// Builds a HapticDevice backend by name. Real backends exist only when CMake found
// their SDK (see device_client/CMakeLists.txt). What the program needs of a backend
// beyond the HapticDevice interface comes with it (Backend), so no caller casts.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "haptic_device.h"
#include "scripted_path.h"
#include "sim_clock.h"
#include "sim_renderer.h"
#include "virtual_hand_device.h"

namespace snapthread::device {

struct BackendConfig {
  std::string name;                   // sim-path | virtual-hand | phantom | delta
  std::optional<ScriptedPath> path;   // required by the simulated backends
  VirtualHandParams hand;
  MicrosClock clock = nullptr;        // simulated backends; null = CLOCK_MONOTONIC
};

// Every name the program knows, built or not.
std::vector<std::string> KnownBackends();
// Names compiled into this binary.
std::vector<std::string> BuiltBackends();
bool BackendNeedsPath(const std::string& name);

// What MakeBackend built.
struct Backend {
  std::unique_ptr<HapticDevice> device;
  // A simulated backend's render thread (its "firmware", sim_renderer.h; owned by the
  // device, not started); null for a real device, which renders in hardware.
  SimRenderer* renderer = nullptr;
};

// device null with *error set for an unknown name, a backend not built into this binary,
// or a simulated backend without a path.
Backend MakeBackend(const BackendConfig& config, std::string* error);

}  // namespace snapthread::device
