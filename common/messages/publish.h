// Publishing a tagged message (auth::Sign) on its channel: in clear, or as a sealed_t
// envelope when the process seals (--encrypt; auth/sealed_message.h). Every snapthread
// sender publishes through these, so one flag decides what leaves the host.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "auth/sealed_message.h"

namespace snapthread::messages {

// Publishes `size` bytes of a tagged encoding; liblcm's result (0 on success), -1 when
// the envelope cannot be made.
inline int PublishEncoded(lcm::LCM* lcm, const std::string& channel, const void* data, std::size_t size) {
  const auth::ByteView out =
      auth::SealForChannel(auth::ByteView{static_cast<const uint8_t*>(data), size}, channel);
  if (out.data == nullptr) return -1;
  return lcm->publish(channel, out.data, static_cast<unsigned int>(out.size));
}

// Encodes `msg` (in the calling thread's buffer, reused: allocation-free in steady state)
// and publishes it as PublishEncoded does; -1 when it cannot be encoded.
template <class Msg>
int Publish(lcm::LCM* lcm, const std::string& channel, const Msg& msg) {
  thread_local std::vector<uint8_t> buffer;
  const int n = msg.getEncodedSize();
  if (n <= 0) return -1;
  if (static_cast<std::size_t>(n) > buffer.size()) buffer.resize(2 * static_cast<std::size_t>(n));
  if (msg.encode(buffer.data(), 0, n) != n) return -1;
  return PublishEncoded(lcm, channel, buffer.data(), static_cast<std::size_t>(n));
}

}  // namespace snapthread::messages
