// PNG output for screenshots (libpng).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace snapthread::viewer {

// Writes 8-bit RGB rows, top row first. Returns false with the reason in *error.
bool WritePngRgb(const std::string& path, int width, int height,
                 const std::vector<uint8_t>& rgb_top_down, std::string* error);

}  // namespace snapthread::viewer
