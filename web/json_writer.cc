#include "json_writer.h"

#include <charconv>
#include <cmath>
#include <cstdio>

namespace snapthread::web {

void JsonWriter::Key(std::string_view key) {
  if (need_comma_) text_ += ',';
  need_comma_ = true;
  if (!key.empty()) {
    AppendEscaped(key);
    text_ += ':';
  }
}

JsonWriter& JsonWriter::BeginObject() {
  Key({});
  text_ += '{';
  need_comma_ = false;
  return *this;
}

JsonWriter& JsonWriter::EndObject() {
  text_ += '}';
  need_comma_ = true;
  return *this;
}

JsonWriter& JsonWriter::BeginArray(std::string_view key) {
  Key(key);
  text_ += '[';
  need_comma_ = false;
  return *this;
}

JsonWriter& JsonWriter::EndArray() {
  text_ += ']';
  need_comma_ = true;
  return *this;
}

void JsonWriter::AppendDouble(double value) {
  if (!std::isfinite(value)) {
    text_ += "null";
    return;
  }
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  text_.append(buffer, result.ptr);
}

JsonWriter& JsonWriter::Number(std::string_view key, double value) {
  Key(key);
  AppendDouble(value);
  return *this;
}

JsonWriter& JsonWriter::Int(std::string_view key, int64_t value) {
  Key(key);
  text_ += std::to_string(value);
  return *this;
}

JsonWriter& JsonWriter::Bool(std::string_view key, bool value) {
  Key(key);
  text_ += value ? "true" : "false";
  return *this;
}

JsonWriter& JsonWriter::String(std::string_view key, std::string_view value) {
  Key(key);
  AppendEscaped(value);
  return *this;
}

JsonWriter& JsonWriter::Numbers(std::string_view key, const double* values, int n) {
  BeginArray(key);
  for (int i = 0; i < n; ++i) {
    if (i > 0) text_ += ',';
    AppendDouble(values[i]);
  }
  return EndArray();
}

namespace {

// The length of the well-formed UTF-8 sequence at the start of `s` (RFC 3629: no
// overlong forms, no surrogates, at most U+10FFFF), 0 when it is not one.
size_t Utf8SequenceLength(std::string_view s) {
  const auto b = [&](size_t i) { return static_cast<unsigned char>(s[i]); };
  const unsigned char c = b(0);
  if (c < 0x80) return 1;
  size_t n;
  unsigned char lo = 0x80, hi = 0xbf;  // the second byte's range
  if (c >= 0xc2 && c <= 0xdf) n = 2;
  else if (c >= 0xe0 && c <= 0xef) n = 3, lo = c == 0xe0 ? 0xa0 : 0x80, hi = c == 0xed ? 0x9f : 0xbf;
  else if (c >= 0xf0 && c <= 0xf4) n = 4, lo = c == 0xf0 ? 0x90 : 0x80, hi = c == 0xf4 ? 0x8f : 0xbf;
  else return 0;
  if (s.size() < n || b(1) < lo || b(1) > hi) return 0;
  for (size_t i = 2; i < n; ++i) {
    if (b(i) < 0x80 || b(i) > 0xbf) return 0;
  }
  return n;
}

}  // namespace

// Strings from messages are any bytes: a WebSocket text message must be UTF-8 (a browser
// closes the connection on anything else), so each byte that does not start a
// well-formed sequence is written as U+FFFD.
void JsonWriter::AppendEscaped(std::string_view value) {
  text_ += '"';
  for (size_t i = 0; i < value.size();) {
    const char c = value[i];
    const size_t n = Utf8SequenceLength(value.substr(i));
    if (n == 0) {
      text_ += "\\ufffd";
      i += 1;
      continue;
    }
    if (n > 1) {
      text_.append(value.substr(i, n));
      i += n;
      continue;
    }
    i += 1;
    switch (c) {
      case '"': text_ += "\\\""; break;
      case '\\': text_ += "\\\\"; break;
      case '\n': text_ += "\\n"; break;
      case '\t': text_ += "\\t"; break;
      case '\r': text_ += "\\r"; break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          char escaped[8];
          std::snprintf(escaped, sizeof escaped, "\\u%04x", static_cast<unsigned>(c));
          text_ += escaped;
        } else {
          text_ += c;
        }
    }
  }
  text_ += '"';
}

}  // namespace snapthread::web
