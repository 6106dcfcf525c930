// What the server needs from the network, as an interface tests can replace (the
// device's DeviceTransport, device_client/transport.h, seen from the other side):
// publish the server's messages, and hand the datagrams received on the session's input
// channels to the inbound gate. Production uses LcmServerTransport
// (lcm_server_transport.h); the in-process tests an in-memory transport
// (tests/service/server_memory_transport.h), so a whole Server runs without LCM.
//
// A transport only moves bytes: building and signing a message is the publisher's job
// (publisher.h), decoding, authenticating and counting a received one the gate's
// (inbound_gate.h), so a transport cannot let a bad packet through or send an unsigned
// one.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>

#include "snapthread/command_reply_t.hpp"
#include "snapthread/force_model_t.hpp"
#include "snapthread/solver_status_t.hpp"
#include "snapthread/thread_shape_t.hpp"

namespace snapthread::server {

// The transport could not start (LCM on a bad URL, no multicast route): exit code 1 in
// snapthread-server.
class LcmInitError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Where a transport hands what it received: the datagram exactly as it came off the
// wire (undecoded). Called on the thread that calls ServerTransport::Receive. Never
// throws.
class InboundSink {
 public:
  virtual ~InboundSink() = default;
  virtual void OnDeviceState(const void* data, size_t size) = 0;  // <SESSION>_DEVICE_STATE
  virtual void OnCommand(const void* data, size_t size) = 0;      // <SESSION>_COMMAND
};

class ServerTransport {
 public:
  virtual ~ServerTransport() = default;

  // Publish on <SESSION>_FORCE_MODEL / _SHAPE / _SOLVER_STATUS / _COMMAND_REPLY
  // (messages/channels.h).
  // False when the transport refused (counted by the caller, never fatal). Never throw.
  // Called from the solve thread only.
  virtual bool PublishForceModel(const force_model_t& msg) = 0;
  virtual bool PublishShape(const thread_shape_t& msg) = 0;
  virtual bool PublishSolverStatus(const solver_status_t& msg) = 0;
  virtual bool PublishCommandReply(const command_reply_t& msg) = 0;

  // Hands what arrived to sink, waiting at most wait_ms for it. Returns how many
  // messages it handed over, or -1 when the transport failed (the caller backs off).
  // Called from the receive thread only. Never throws.
  virtual int Receive(int wait_ms, InboundSink* sink) = 0;

  // Where it talks, for the start-up log line ("udpm://...", "memory").
  virtual std::string Describe() const = 0;
};

}  // namespace snapthread::server
