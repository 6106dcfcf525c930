// Table-driven message checks. Each message type declares ONE table (validate.cc): its
// fields in .lcm order, how each travels on the wire and the rule it must meet. Two
// generic walkers read the table:
//  * CheckWire, before decoding: lcm-gen 1.3.1's decoders trust the wire (a string length
//    of INT32_MIN makes them read 2 GB past the buffer, a corrupted count makes them
//    allocate whatever it says), so every string length and array count is checked
//    against the bytes actually there, and the fields must fill the buffer exactly.
//    Offsets follow from the table; none is written by hand.
//  * CheckFields, after decoding: finiteness, integer ranges, string sizes and the few
//    rules of their own (a quaternion's norm, rows that agree with their count).
// Adding a field to a message is one row in its table.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>
#include <span>
#include <string>
#include <type_traits>

namespace snapthread::messages {

// Largest string accepted in any message field, bytes.
inline constexpr size_t kMaxStringBytes = 4096;

// How a field is encoded by LCM (big-endian; a string is an int32 length that counts the
// terminating NUL, then the bytes).
enum class Wire {
  kInt8,        // `count` of them (byte mac[32] -> 32)
  kInt32,
  kInt64,
  kDouble,      // `count` doubles (a fixed array: double[3] -> 3, double[3][3] -> 9)
  kString,
  kCount,       // an int32 that sizes the following kCountedRows field
  kCountedRows  // (last kCount) rows of `count` doubles
};

template <class T>
struct Field {
  const char* name;
  Wire wire;
  int count = 1;  // kDouble: values; kCountedRows: doubles per row
  // Rules; each one that is set applies.
  const double* (*doubles)(const T&) = nullptr;      // `count` finite values
  const std::string* (*text)(const T&) = nullptr;    // at most kMaxStringBytes
  int64_t (*integer)(const T&) = nullptr;            // in [min, max] (kCount: on the wire too)
  int64_t min = 0;
  int64_t max = 0;
  bool (*rule)(const T&, std::string* why) = nullptr;  // a rule of its own
};

namespace field_table_internal {

inline bool Fail(std::string* why, const std::string& text) {
  if (why) *why = text;
  return false;
}

inline int WireBytes(Wire w) {
  switch (w) {
    case Wire::kInt8: return 1;
    case Wire::kInt32: return 4;
    case Wire::kInt64: return 8;
    case Wire::kDouble: return 8;
    default: return 0;
  }
}

inline bool ReadI32(const uint8_t* p, int size, int* pos, int32_t* out) {
  if (*pos < 0 || size - *pos < 4) return false;
  uint32_t v = 0;
  for (int i = 0; i < 4; ++i) v = (v << 8) | p[*pos + i];
  *pos += 4;
  std::memcpy(out, &v, 4);
  return true;
}

}  // namespace field_table_internal

// Walks an encoded T (8-byte hash first) through every field of its table: each string
// length must lie in [1, bytes left] and end in the string's only NUL, each count in its
// [min, max] with its rows within the buffer, and the fields must fill the buffer
// exactly. So a table that misses a field of the .lcm refuses every message (the tests
// see it at once), and lcm-gen's decoder never meets a length it would trust blindly.
template <class T>
bool CheckWire(std::span<const Field<T>> fields, const void* data, int size, std::string* why) {
  using namespace field_table_internal;
  const std::string type = T::getTypeName();
  const auto* p = static_cast<const uint8_t*>(data);
  int64_t pos = 8;                 // the type hash
  int64_t rows = 0;
  for (size_t i = 0; i < fields.size(); ++i) {
    const Field<T>& f = fields[i];
    switch (f.wire) {
      case Wire::kString: {
        if (pos > size) return Fail(why, type + " truncated");
        int ipos = static_cast<int>(pos);
        int32_t len = 0;
        // The length includes the terminating NUL.
        if (!ReadI32(p, size, &ipos, &len) || len < 1 || len > size - ipos) {
          return Fail(why, type + ": malformed string length (" + f.name + ")");
        }
        // lcm-gen's decoder reads the string up to its first NUL and skips the rest: a
        // missing terminator or an embedded NUL would be accepted and lost (the message
        // would not re-encode to the bytes received).
        if (p[ipos + len - 1] != 0 || std::memchr(p + ipos, 0, len - 1) != nullptr) {
          return Fail(why, type + ": string " + f.name + " is not one NUL-terminated string");
        }
        pos = ipos + static_cast<int64_t>(len);
        break;
      }
      case Wire::kCount: {
        if (pos > size) return Fail(why, type + " truncated");
        int ipos = static_cast<int>(pos);
        int32_t n = 0;
        if (!ReadI32(p, size, &ipos, &n)) return Fail(why, type + " truncated");
        if (n < f.min || n > f.max) {
          return Fail(why, type + ": " + f.name + " " + std::to_string(n) + " outside [" +
                               std::to_string(f.min) + ", " + std::to_string(f.max) + "]");
        }
        rows = n;
        pos = ipos;
        break;
      }
      case Wire::kCountedRows: {
        const int64_t bytes = rows * f.count * 8;
        if (pos > size || bytes > size - pos) {
          return Fail(why, type + ": buffer too short for " + std::to_string(rows) + " rows of " +
                               f.name);
        }
        pos += bytes;
        break;
      }
      default:
        pos += static_cast<int64_t>(WireBytes(f.wire)) * f.count;
        break;
    }
  }
  if (pos > size) {
    return Fail(why, type + " truncated (" + std::to_string(size) + " bytes, the fields need " +
                         std::to_string(pos) + ")");
  }
  if (pos < size) {
    return Fail(why, "buffer has " + std::to_string(size - pos) +
                         " trailing bytes after the message");
  }
  return true;
}

// Applies every rule of the table to a decoded (or about to be encoded) message.
template <class T>
bool CheckFields(std::span<const Field<T>> fields, const T& msg, std::string* why) {
  using namespace field_table_internal;
  for (const Field<T>& f : fields) {
    if (f.doubles != nullptr) {
      const double* v = f.doubles(msg);
      for (int i = 0; i < f.count; ++i) {
        if (!std::isfinite(v[i])) return Fail(why, std::string(f.name) + " is not finite");
      }
    }
    if (f.text != nullptr && f.text(msg)->size() > kMaxStringBytes) {
      return Fail(why, std::string(f.name) + " longer than " + std::to_string(kMaxStringBytes) +
                           " bytes");
    }
    if (f.integer != nullptr) {
      const int64_t v = f.integer(msg);
      if (v < f.min || v > f.max) {
        return Fail(why, std::string(f.name) + " " + std::to_string(v) + " outside [" +
                             std::to_string(f.min) + ", " + std::to_string(f.max) + "]");
      }
    }
    if (f.rule != nullptr && !f.rule(msg, why)) return false;
  }
  return true;
}

// ---- building a table row from a member pointer -------------------------------------------
// Wire and default rule follow from the member's type: doubles (scalars and fixed arrays)
// must be finite, strings at most kMaxStringBytes, integers are free unless given a range.
namespace field_table_internal {

template <class P>
struct MemberOf;
template <class C, class V>
struct MemberOf<V C::*> {
  using Class = C;
  using Value = V;
};

template <auto M>
const double* DoublesOf(const typename MemberOf<decltype(M)>::Class& msg) {
  return reinterpret_cast<const double*>(&(msg.*M));  // scalars and (nested) arrays are contiguous
}
template <auto M>
const std::string* TextOf(const typename MemberOf<decltype(M)>::Class& msg) {
  return &(msg.*M);
}
template <auto M>
int64_t IntegerOf(const typename MemberOf<decltype(M)>::Class& msg) {
  return static_cast<int64_t>(msg.*M);
}

}  // namespace field_table_internal

template <auto M>
Field<typename field_table_internal::MemberOf<decltype(M)>::Class> Member(const char* name) {
  using namespace field_table_internal;
  using V = typename MemberOf<decltype(M)>::Value;
  using E = std::remove_all_extents_t<V>;
  Field<typename MemberOf<decltype(M)>::Class> f{name, Wire::kInt64};
  if constexpr (std::is_same_v<E, double>) {
    f.wire = Wire::kDouble;
    f.count = static_cast<int>(sizeof(V) / sizeof(double));
    f.doubles = &DoublesOf<M>;
  } else if constexpr (std::is_same_v<V, std::string>) {
    f.wire = Wire::kString;
    f.text = &TextOf<M>;
  } else {
    static_assert(std::is_integral_v<E>, "a message field is a double, a string or an integer");
    f.wire = sizeof(E) == 1 ? Wire::kInt8 : sizeof(E) == 4 ? Wire::kInt32 : Wire::kInt64;
    f.count = static_cast<int>(sizeof(V) / sizeof(E));  // byte mac[32] -> 32
  }
  return f;
}

// An integer member that must lie in [min, max].
template <auto M>
Field<typename field_table_internal::MemberOf<decltype(M)>::Class> Member(const char* name,
                                                                          int64_t min,
                                                                          int64_t max) {
  auto f = Member<M>(name);
  f.integer = &field_table_internal::IntegerOf<M>;
  f.min = min;
  f.max = max;
  return f;
}

// The int32 count of a variable array, in [min, max] (checked on the wire before decoding).
template <auto M>
Field<typename field_table_internal::MemberOf<decltype(M)>::Class> Count(const char* name,
                                                                         int64_t min,
                                                                         int64_t max) {
  auto f = Member<M>(name, min, max);
  f.wire = Wire::kCount;
  return f;
}

// Rows of `per_row` doubles sized by the preceding Count, checked by `rule`.
template <class T>
Field<T> CountedRows(const char* name, int per_row, bool (*rule)(const T&, std::string*)) {
  Field<T> f{name, Wire::kCountedRows};
  f.count = per_row;
  f.rule = rule;
  return f;
}

// A row with a rule of its own added.
template <class T>
Field<T> With(Field<T> f, bool (*rule)(const T&, std::string*)) {
  f.rule = rule;
  return f;
}

}  // namespace snapthread::messages
