// snapthread-device: the 1 kHz haptic device client (see device_client_app.h).
#include "device_client_app.h"

int main(int argc, char** argv) {
  snapthread::device::DeviceClientOptions options;
  const int parsed = snapthread::device::ParseDeviceClientArgs(argc, argv, &options);
  if (parsed >= 0) return parsed;
  return snapthread::device::RunDeviceClient(options);
}
