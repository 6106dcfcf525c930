// Validation of every snapthread message after decoding. Network input is untrusted:
// a message is used only when it decodes exactly (no trailing bytes) and passes
// Validate(). LCM's generated encoders do not check array counts and its decoders
// trust them, so counts are checked here, before encode and after decode.
#pragma once

#include <exception>
#include <string>

#include <lcm/lcm-cpp.hpp>

#include "messages/field_table.h"
#include "snapthread/command_reply_t.hpp"
#include "snapthread/command_t.hpp"
#include "snapthread/device_state_t.hpp"
#include "snapthread/device_status_t.hpp"
#include "snapthread/force_model_t.hpp"
#include "snapthread/solver_status_t.hpp"
#include "snapthread/thread_shape_t.hpp"

namespace snapthread::messages {

// Largest thread_shape_t the service accepts (positions are 24 bytes per node).
inline constexpr int kMaxShapeNodes = 100000;
// Accepted range of a quaternion's norm: clients send unit quaternions; anything far off
// is a corrupted message, not a rounding error.
inline constexpr double kMinQuaternionNorm = 0.5;
inline constexpr double kMaxQuaternionNorm = 2.0;
// Most grasps a scene may name (thread_shape_t.grasps rows).
inline constexpr int kMaxGrasps = 16;
// Longest reason a command reply carries (the server cuts a longer one).
inline constexpr int kMaxCommandReplyBytes = 1024;

// Each returns true when the message is usable; otherwise false with the reason in
// *why (if why is non-null). Never throws. The rules are the message's field table
// (validate.cc, one per type); a force model is checked here and nowhere else.
bool Validate(const device_state_t& msg, std::string* why);
bool Validate(const force_model_t& msg, std::string* why);
bool Validate(const thread_shape_t& msg, std::string* why);
bool Validate(const solver_status_t& msg, std::string* why);
bool Validate(const device_status_t& msg, std::string* why);
bool Validate(const command_t& msg, std::string* why);
bool Validate(const command_reply_t& msg, std::string* why);

// Checks an encoded buffer before handing it to the generated decoder: every string
// length and array count of T against the bytes there, and that T's fields fill the
// buffer exactly (field_table.h: CheckWire).
// Defined for the seven message types above.
template <class T>
bool PreDecodeCheck(const void* data, int size, std::string* why);

// Decodes `data` into *out and validates it. False (with *why) for a malformed buffer
// (wrong hash, truncated, trailing bytes, absurd counts) or an invalid message.
// Never throws: safe inside LCM handlers.
template <class T>
bool DecodeAndValidate(const void* data, int size, T* out, std::string* why) {
  try {
    if (data == nullptr || size <= 0) {
      if (why) *why = "empty buffer";
      return false;
    }
    // The type fingerprint first: another type (or another version of this one) is named
    // as such, not as a "malformed buffer".
    int64_t hash = 0;
    if (__int64_t_decode_array(data, 0, size, &hash, 1) != 8) {
      if (why) *why = std::string(T::getTypeName()) + " truncated (" + std::to_string(size) + " bytes)";
      return false;
    }
    if (hash != T::getHash()) {
      if (why) *why = std::string("wrong type fingerprint: not a ") + T::getTypeName() + " of this version";
      return false;
    }
    if (!PreDecodeCheck<T>(data, size, why)) return false;
    const int used = out->decode(data, 0, size);
    if (used < 0) {
      if (why) *why = "malformed or truncated buffer (" + std::to_string(size) + " bytes)";
      return false;
    }
    if (used != size) {
      if (why) {
        *why = "buffer has " + std::to_string(size - used) + " trailing bytes after the message";
      }
      return false;
    }
    return Validate(*out, why);
  } catch (const std::exception& e) {
    // The generated decoders throw std::length_error / std::bad_alloc for corrupted
    // string lengths; a handler must not let that escape into LCM.
    if (why) *why = std::string("decode failed: ") + e.what();
    return false;
  } catch (...) {
    if (why) *why = "decode failed";
    return false;
  }
}

template <class T>
bool DecodeAndValidate(const lcm::ReceiveBuffer* buf, T* out, std::string* why) {
  if (buf == nullptr) {
    if (why) *why = "null receive buffer";
    return false;
  }
  if (buf->data_size > static_cast<uint32_t>(1 << 30)) {
    if (why) *why = "buffer too large";
    return false;
  }
  return DecodeAndValidate(buf->data, static_cast<int>(buf->data_size), out, why);
}

}  // namespace snapthread::messages
