// Reads the viewer's and the report's PNGs back for the image assertions.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace snapthread::viewer_test {

struct Image {
  int width = 0;
  int height = 0;
  std::vector<uint8_t> rgb;  // top row first
  const uint8_t* At(int x, int y) const { return &rgb[(size_t(y) * width + x) * 3]; }
};
// Reads an 8-bit PNG (any colour type, converted to RGB). False with *error when invalid.
bool ReadPng(const std::string& path, Image* image, std::string* error);

}  // namespace snapthread::viewer_test
