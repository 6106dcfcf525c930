// Subscribe an object's member function to an LCM channel, without the member-function
// overloads of lcm::LCM::subscribe.
//
// Why: those overloads (lcm::LCMMHSubscription and LCMMHUntypedSubscription in
// lcm-cpp-impl.hpp) call the handler through a pointer-to-member-function stored at run
// time. GCC 12 with -fsanitize=undefined (the vptr check) instruments that call wrongly:
// on the non-virtual branch of the call it checks the object against a register it never
// set, so UBSan reports "member access within misaligned address 0x5" or "wrong dynamic
// type" depending on what the caller (liblcm, uninstrumented) left in that register. It
// is a false report, it is deterministic per call path, clang does not do it, and it made
// every LCM-dispatching test fail under the sanitizer build (see the README's Tests
// section; also dotnet/runtime#73927, "ubsan failure when calling through pointer to
// member function", GCC 10-12). Here the member function is a template argument, so the
// call is direct, and liblcm calls a plain function with a context (subscribeFunction).
// Usage (server/lcm_server_transport.cc):
//   sub = messages::Subscribe<&LcmServerTransport::HandleDeviceState>(lcm, channel, this);
// the handler is (const lcm::ReceiveBuffer*, const std::string& channel) or, typed,
// (const lcm::ReceiveBuffer*, const std::string& channel, const Msg*) (typed: liblcm decodes,
// so a sealed message never reaches it; snapthread's receivers are untyped). Unsubscribe with
// lcm.unsubscribe(sub) as before.
#pragma once

#include <string>

#include <lcm/lcm-cpp.hpp>

#include "auth/sealed_message.h"

namespace snapthread::messages {

namespace subscribe_detail {

// A sealed_t envelope (auth/sealed_message.h) opened with the process's read key stands
// in for the message it holds, so every handler sees the message as if sent in clear. An
// envelope that does not open is passed on as it came: its type fingerprint is none the
// handler decodes, so the handler refuses and counts it as malformed.
inline const lcm::ReceiveBuffer* Unsealed(const lcm::ReceiveBuffer* rbuf, const std::string& channel,
                                          lcm::ReceiveBuffer* opened) {
  if (!auth::IsSealed(rbuf->data, rbuf->data_size)) return rbuf;
  const auto plain = auth::OpenSealed(rbuf->data, rbuf->data_size, channel);
  if (!plain) return rbuf;
  opened->data = const_cast<uint8_t*>(plain->data);
  opened->data_size = static_cast<uint32_t>(plain->size);
  opened->recv_utime = rbuf->recv_utime;
  return opened;
}

template <auto Method>
struct MemberHandler;

template <class Class, void (Class::*Method)(const lcm::ReceiveBuffer*, const std::string&)>
struct MemberHandler<Method> {
  static lcm::Subscription* Subscribe(lcm::LCM* lcm, const std::string& channel,
                                      Class* self) {
    return lcm->subscribeFunction(channel, &Call, self);
  }
  static void Call(const lcm::ReceiveBuffer* rbuf, const std::string& channel, Class* self) {
    lcm::ReceiveBuffer opened{};
    (self->*Method)(Unsealed(rbuf, channel, &opened), channel);
  }
};

template <class Class, class Msg,
          void (Class::*Method)(const lcm::ReceiveBuffer*, const std::string&, const Msg*)>
struct MemberHandler<Method> {
  static lcm::Subscription* Subscribe(lcm::LCM* lcm, const std::string& channel,
                                      Class* self) {
    return lcm->subscribeFunction(channel, &Call, self);
  }
  static void Call(const lcm::ReceiveBuffer* rbuf, const std::string& channel,
                   const Msg* msg, Class* self) {
    (self->*Method)(rbuf, channel, msg);
  }
};

}  // namespace subscribe_detail

// Subscribes self->Method to channel (an LCM channel regex); returns the subscription
// (nullptr if lcm is not good), which lcm->unsubscribe() takes.
template <auto Method, class Class>
lcm::Subscription* Subscribe(lcm::LCM* lcm, const std::string& channel, Class* self) {
  return subscribe_detail::MemberHandler<Method>::Subscribe(lcm, channel, self);
}

template <auto Method, class Class>
lcm::Subscription* Subscribe(lcm::LCM& lcm, const std::string& channel, Class* self) {
  return Subscribe<Method>(&lcm, channel, self);
}

}  // namespace snapthread::messages
