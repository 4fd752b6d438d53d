// An RGBA8 image in memory (top row first) and its PNG encoding through libpng. Screenshots
// are written with write_png, which never leaves a half-written file: the bytes go to a
// temporary file that is renamed over the target only when complete.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace ballpit {

struct Image {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgba;  // width * height * 4 bytes, top row first

  const std::uint8_t* pixel(int x, int y) const { return &rgba[(static_cast<std::size_t>(y) * width + x) * 4]; }
};

std::string encode_png(const Image& image);
// Throws ballpit::Error (naming `what`, e.g. the file) if the bytes are not a PNG libpng reads.
Image decode_png(const std::string& bytes, const std::string& what = "PNG data");
// Encodes and writes atomically; throws ballpit::Error naming the path on failure.
void write_png(const std::string& path, const Image& image);
Image read_png(const std::string& path);

}  // namespace ballpit
