#include "png_image.h"

#include <png.h>

namespace snapthread::viewer_test {

bool ReadPng(const std::string& path, Image* image, std::string* error) {
  png_image img{};
  img.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&img, path.c_str())) {
    *error = std::string("not a readable PNG: ") + img.message;
    return false;
  }
  img.format = PNG_FORMAT_RGB;
  image->width = int(img.width);
  image->height = int(img.height);
  image->rgb.assign(PNG_IMAGE_SIZE(img), 0);
  if (!png_image_finish_read(&img, nullptr, image->rgb.data(), 0, nullptr)) {
    *error = std::string("PNG decode failed: ") + img.message;
    png_image_free(&img);
    return false;
  }
  return true;
}

}  // namespace snapthread::viewer_test
