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

void JsonWriter::AppendEscaped(std::string_view value) {
  text_ += '"';
  for (const char c : value) {
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
