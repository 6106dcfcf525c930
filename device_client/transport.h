// What snapthread-device needs from the network, as an interface tests can replace
// (after Drake's DrakeLcmInterface): publish the device's messages, poll for received
// force models. Production uses LcmDeviceTransport (lcm_transport.h); the unit tests an
// in-memory transport, so a whole DeviceClient runs without LCM.
//
// Building a message is the DeviceClient's job and happens apart from sending it; a
// transport only moves bytes. Nothing here is ever called from the servo thread.
#pragma once

#include <functional>

#include "snapthread/device_state_t.hpp"
#include "snapthread/device_status_t.hpp"

namespace snapthread::device {

class DeviceTransport {
 public:
  // Receives one force_model_t exactly as it came off the wire (undecoded: decoding and
  // validation are the receiver's, so a transport cannot let a bad packet through).
  using ForceModelSink = std::function<void(const void* data, int size)>;

  virtual ~DeviceTransport() = default;

  // Publish on <SESSION>_DEVICE_STATE / <SESSION>_DEVICE_STATUS. False when the
  // transport refused (counted by the caller, never fatal). Never throw.
  virtual bool PublishDeviceState(const device_state_t& msg) = 0;
  virtual bool PublishDeviceStatus(const device_status_t& msg) = 0;

  // Hands every force model received since the last call to sink, waiting at most
  // wait_ms for the first one (0: never waits). Returns the number handed over, or -1
  // when the transport failed (the caller backs off; the watchdog fades the force
  // meanwhile). Never throws, even when sink does.
  virtual int PollForceModels(int wait_ms, const ForceModelSink& sink) = 0;
};

}  // namespace snapthread::device
