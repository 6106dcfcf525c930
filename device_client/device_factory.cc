#include "device_factory.h"

#include <utility>

#include "realtime/clock.h"
#include "sim_path_device.h"
#if SNAPTHREAD_HAVE_PHANTOM
#include "phantom_device.h"
#endif
#if SNAPTHREAD_HAVE_DELTA
#include "delta_device.h"
#endif

namespace snapthread::device {

std::vector<std::string> KnownBackends() { return {"sim-path", "virtual-hand", "phantom", "delta"}; }

std::vector<std::string> BuiltBackends() {
  std::vector<std::string> b = {"sim-path", "virtual-hand"};
#if SNAPTHREAD_HAVE_PHANTOM
  b.push_back("phantom");
#endif
#if SNAPTHREAD_HAVE_DELTA
  b.push_back("delta");
#endif
  return b;
}

bool BackendNeedsPath(const std::string& name) {
  return name == "sim-path" || name == "virtual-hand";
}

namespace {

// A simulated backend with its render thread.
template <typename Device, typename... Args>
Backend Simulated(Args&&... args) {
  auto device = std::make_unique<Device>(std::forward<Args>(args)...);
  SimRenderer* renderer = &device->renderer();
  return Backend{std::move(device), renderer};
}

}  // namespace

Backend MakeBackend(const BackendConfig& config, std::string* error) {
  const MicrosClock clock = config.clock ? config.clock : &realtime::MonotonicMicros;
  if (BackendNeedsPath(config.name) && !config.path) {
    if (error) *error = "backend " + config.name + " needs a path (--scene or --path-csv)";
    return {};
  }
  if (config.name == "sim-path") return Simulated<SimPathDevice>(*config.path, clock);
  if (config.name == "virtual-hand") return Simulated<VirtualHandDevice>(*config.path, config.hand, clock);
  if (config.name == "phantom") {
#if SNAPTHREAD_HAVE_PHANTOM
    return Backend{MakePhantomDevice()};
#else
    if (error) {
      *error = "backend phantom was not built: OpenHaptics (HD/hd.h, libHD) was not found "
               "when CMake configured this build";
    }
    return {};
#endif
  }
  if (config.name == "delta") {
#if SNAPTHREAD_HAVE_DELTA
    return Backend{MakeDeltaDevice()};
#else
    if (error) {
      *error = "backend delta was not built: the Force Dimension SDK (dhdc.h, libdhd) was "
               "not found when CMake configured this build";
    }
    return {};
#endif
  }
  if (error) {
    *error = "unknown backend '" + config.name + "' (expected sim-path, virtual-hand, phantom or delta)";
  }
  return {};
}

}  // namespace snapthread::device
