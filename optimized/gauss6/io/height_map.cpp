// Height-map images for textures (scene.h: read_height_map, write_height_map):
// PNG through libpng's simplified API, which converts any bit depth and colour
// type to 16-bit grey. Load time only.
#include <png.h>

#include <cstdint>
#include <string>
#include <vector>

#include "gauss6/io/regular_file.h"
#include "gauss6/io/scene.h"

namespace gauss6 {

namespace {
constexpr uint64_t kMaxHeightMapPixels = uint64_t(1) << 26;
}  // namespace

bool read_height_map(const std::string& path, HeightMapImage* out, std::string* error) {
  // A PNG of 2^26 16-bit pixels with its chunks' overhead stays far below 1 GiB.
  if (const std::string problem = regular_file_problem(path, uint64_t(1) << 30); !problem.empty()) {
    *error = path + ": " + problem;
    return false;
  }
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&image, path.c_str())) {
    *error = path + ": cannot read as PNG (" + image.message + ")";
    return false;
  }
  // The header's size bounds what is allocated: at most 2^26 pixels (8192 x 8192),
  // checked before the buffer exists (a 100-byte file may state 10^6 x 10^6).
  if (static_cast<uint64_t>(image.width) * image.height > kMaxHeightMapPixels) {
    *error = path + ": a height map of " + std::to_string(image.width) + " x " + std::to_string(image.height) +
             " pixels, more than the " + std::to_string(kMaxHeightMapPixels) + " allowed";
    png_image_free(&image);
    return false;
  }
  image.format = PNG_FORMAT_LINEAR_Y;  // 16-bit grey, linear
  std::vector<uint16_t> pixels(static_cast<size_t>(image.width) * image.height);
  if (!png_image_finish_read(&image, nullptr, pixels.data(), 0, nullptr)) {
    *error = path + ": cannot decode PNG (" + image.message + ")";
    png_image_free(&image);
    return false;
  }
  out->width = static_cast<int>(image.width);
  out->height = static_cast<int>(image.height);
  out->values.resize(pixels.size());
  for (size_t i = 0; i < pixels.size(); ++i) out->values[i] = static_cast<float>(pixels[i] / 65535.0);
  return true;
}

bool write_height_map(const std::string& path, const HeightMapImage& h, std::string* error) {
  if (h.width < 1 || h.height < 1 || h.values.size() != static_cast<size_t>(h.width) * h.height) {
    *error = path + ": bad image size";
    return false;
  }
  std::vector<uint8_t> pixels(h.values.size());
  for (size_t i = 0; i < pixels.size(); ++i) {
    const float v = h.values[i] < 0 ? 0.f : (h.values[i] > 1 ? 1.f : h.values[i]);
    pixels[i] = static_cast<uint8_t>(v * 255.f + 0.5f);
  }
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  image.width = static_cast<png_uint_32>(h.width);
  image.height = static_cast<png_uint_32>(h.height);
  image.format = PNG_FORMAT_GRAY;
  if (!png_image_write_to_file(&image, path.c_str(), 0, pixels.data(), 0, nullptr)) {
    *error = path + ": cannot write PNG (" + image.message + ")";
    return false;
  }
  return true;
}

}  // namespace gauss6
