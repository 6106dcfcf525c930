#include "device_factory.h"

#include "sim_path_device.h"
#include "realtime/clock.h"
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

std::unique_ptr<HapticDevice> MakeDevice(const BackendConfig& config, std::string* error) {
  const MicrosClock clock = config.clock ? config.clock : &realtime::MonotonicMicros;
  if (BackendNeedsPath(config.name) && !config.path) {
    if (error) *error = "backend " + config.name + " needs a path (--scene or --path-csv)";
    return nullptr;
  }
  if (config.name == "sim-path") return std::make_unique<SimPathDevice>(*config.path, clock);
  if (config.name == "virtual-hand") {
    return std::make_unique<VirtualHandDevice>(*config.path, config.hand, clock);
  }
  if (config.name == "phantom") {
#if SNAPTHREAD_HAVE_PHANTOM
    return std::make_unique<PhantomDevice>();
#else
    if (error) {
      *error = "backend phantom was not built: OpenHaptics (HD/hd.h, libHD) was not found "
               "when CMake configured this build";
    }
    return nullptr;
#endif
  }
  if (config.name == "delta") {
#if SNAPTHREAD_HAVE_DELTA
    return std::make_unique<DeltaDevice>();
#else
    if (error) {
      *error = "backend delta was not built: the Force Dimension SDK (dhdc.h, libdhd) was "
               "not found when CMake configured this build";
    }
    return nullptr;
#endif
  }
  if (error) {
    *error = "unknown backend '" + config.name + "' (expected sim-path, virtual-hand, phantom or delta)";
  }
  return nullptr;
}

}  // namespace snapthread::device
