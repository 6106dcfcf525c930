// A minimal JSON text builder for the bridge's messages to the page: objects, arrays,
// numbers (shortest round-trip form, std::to_chars; non-finite numbers become null, which
// JSON has no other spelling for) and escaped strings. Not a parser.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace snapthread::web {

class JsonWriter {
 public:
  JsonWriter& BeginObject();
  JsonWriter& EndObject();
  JsonWriter& BeginArray(std::string_view key = {});
  JsonWriter& EndArray();
  // Keys are only given inside objects; inside arrays pass none.
  JsonWriter& Number(std::string_view key, double value);
  JsonWriter& Int(std::string_view key, int64_t value);
  JsonWriter& Bool(std::string_view key, bool value);
  JsonWriter& String(std::string_view key, std::string_view value);
  // `values[0..n)` as a flat array.
  JsonWriter& Numbers(std::string_view key, const double* values, int n);
  // An array element (no key).
  JsonWriter& Element(double value) { return Number({}, value); }

  const std::string& text() const { return text_; }
  std::string Take() { return std::move(text_); }

 private:
  void Key(std::string_view key);
  void AppendDouble(double value);
  void AppendEscaped(std::string_view value);

  std::string text_;
  bool need_comma_ = false;
};

}  // namespace snapthread::web
