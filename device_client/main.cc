// snapthread-device: the 1 kHz haptic device client (see device_client_app.h).
#include "app/stop_signals.h"
#include "device_client_app.h"

int main(int argc, char** argv) {
  snapthread::device::DeviceClientOptions options;
  if (auto code = snapthread::device::ParseDeviceClientArgs(argc, argv, &options)) return *code;
  // Before any thread (LCM's, the render and servo threads): they inherit the mask.
  snapthread::app::StopSignals stop;
  snapthread::device::ReloadSignal reload;  // SIGHUP reloads --key, never stops
  return snapthread::device::RunDeviceClient(options, &stop, &reload);
}
